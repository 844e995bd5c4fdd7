"""Counter-based hash shared bit for bit by numpy and GLSL (``shaders/lib/hash.glsl``).

Everything is uint32 arithmetic with wraparound, so the GLSL ``uint`` code and this numpy code
give identical results on every platform.

* :func:`lowbias32` — Chris Wellons' 2-multiply integer finalizer (bias ~0.17), a bijection on
  uint32: ``x ^= x>>16; x *= 0x7feb352d; x ^= x>>15; x *= 0x846ca68b; x ^= x>>16``.
* :func:`stream_key` — a pair of 32-bit keys ``(ka, kb)`` for one random stream, derived from
  ``(seed, step, rule, plane)`` by a lowbias32 chain. Keys do not depend on the cell, so GPU code
  gets them as uniforms (computed here) and only pays :func:`hash_counter` per counter value.
* :func:`hash_counter` — ``lowbias32(lowbias32(counter + ka) ^ kb)``: the random uint32 of one
  counter value (a cell or a 32-cell word) in the stream ``(ka, kb)``. Two rounds with two keys
  so that different streams are not index-shifted copies of one another.
* :func:`hash4` — the whole chain for one ``(counter, seed, step, stream)`` in one call.
"""
from __future__ import annotations

import numpy as np

_M1 = np.uint32(0x7FEB352D)
_M2 = np.uint32(0x846CA68B)
_KB_SALT = np.uint32(0x68E31DA4)
_SEED_SALT = np.uint32(0x9E3779B9)

__all__ = ["lowbias32", "stream_key", "hash_counter", "hash4"]


def _u32(x) -> np.ndarray:
    """uint32 view of ints/arrays, reduced modulo 2**32 (negative ints wrap like GLSL uint())."""
    if isinstance(x, np.ndarray) and x.dtype == np.uint32:
        return x
    return np.asarray(np.asarray(x, dtype=np.int64) & 0xFFFFFFFF, dtype=np.uint32)


def lowbias32(x) -> np.ndarray:
    """The lowbias32 bijection on uint32 (array in, uint32 array out)."""
    x = _u32(x).copy()
    with np.errstate(over="ignore"):
        x ^= x >> np.uint32(16)
        x *= _M1
        x ^= x >> np.uint32(15)
        x *= _M2
        x ^= x >> np.uint32(16)
    return x


def stream_key(seed, step, rule, plane) -> tuple[np.ndarray, np.ndarray]:
    """Keys ``(ka, kb)`` of the stream for ``(seed, step, rule, plane)`` (all taken mod 2**32).

    ``rule`` and ``plane`` are combined as ``rule * 256 + plane`` (rule < 2**24, plane < 256).
    """
    seed, step, rule, plane = _u32(seed), _u32(step), _u32(rule), _u32(plane)
    with np.errstate(over="ignore"):
        k = lowbias32(seed ^ _SEED_SALT)
        k = lowbias32(k ^ step)
        k = lowbias32(k ^ (rule * np.uint32(256) + plane))
    return k, lowbias32(k ^ _KB_SALT)


def hash_counter(counter, ka, kb) -> np.ndarray:
    """``lowbias32(lowbias32(counter + ka) ^ kb)`` in uint32."""
    counter, ka, kb = _u32(counter), _u32(ka), _u32(kb)
    with np.errstate(over="ignore"):
        return lowbias32(lowbias32(counter + ka) ^ kb)


def hash4(counter, seed, step, stream) -> np.ndarray:
    """The uint32 hash of ``counter`` in stream ``stream`` (= rule*256+plane) of ``step``/``seed``."""
    stream = _u32(stream)
    ka, kb = stream_key(seed, step, stream >> np.uint32(8), stream & np.uint32(255))
    return hash_counter(counter, ka, kb)
