"""Numpy reference of one whole automaton step, bit for bit what the GPU computes.

Written cell by cell (bool arrays indexed ``[x, y, z]``, y is height) and independently of the GPU
code's tricks (no bit-sliced early exit, no word shifts), so the tests compare two formulations.

Random numbers (see :mod:`atmos.hashing`): cell ``(x, y, z)`` belongs to the 32-cell word
``w = x // 32 + nwx * (y + ny * z)`` with ``nwx = ceil(nx / 32)`` and bit ``x % 32``. For rule
``r`` (0 extinction, 1 humidity, 2 activation) and plane ``j`` (0..PRECISION_BITS-1) of step ``s``
the word ``hash_counter(w, *stream_key(seed, s, r, j))`` supplies bit ``j`` of the cell's random
number ``U`` (its bit ``x % 32``), so ``U`` is uniform on ``[0, 2**PRECISION_BITS)``. A probability
``p`` becomes the threshold ``T = floor(p * 2**PRECISION_BITS + 0.5)`` (exact in float64 and in
float32), and the Bernoulli event is ``U < T``: probability ``T / 2**16``, within ``2**-17`` of p;
``p = 0`` never and ``p = 1`` always fires.
"""
from __future__ import annotations

import numpy as np

from atmos.hashing import hash_counter, stream_key

PRECISION_BITS = 16
RULE_EXT, RULE_HUM, RULE_ACT = 0, 1, 2

#: Neighbourhood of f_act (eq. 2.4 of the thesis, with its vertical axis k mapped to our y):
#: ±1 on x, y, z; ±2 on x and z; only −2 on the height axis y (no act(i, j, k+2) term).
NEIGHBOURS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1),
              (2, 0, 0), (-2, 0, 0), (0, 0, 2), (0, 0, -2), (0, -2, 0))


def threshold(p) -> np.ndarray:
    """uint32 threshold(s) ``floor(p * 2**16 + 0.5)`` in ``[0, 65536]`` of probabilities in [0, 1]."""
    return np.floor(np.asarray(p, dtype=np.float64) * float(1 << PRECISION_BITS) + 0.5).astype(np.uint32)


def neighbour(a: np.ndarray, offset) -> np.ndarray:
    """``b[c] = a[c + offset]`` with False outside the volume."""
    out = np.zeros_like(a)
    src, dst = [], []
    for d, n in zip(offset, a.shape):
        if abs(d) >= n:
            return out
        src.append(slice(max(d, 0), n + min(d, 0)))
        dst.append(slice(max(-d, 0), n - max(d, 0)))
    out[tuple(dst)] = a[tuple(src)]
    return out


def growth(hum, act, cld):
    """Eq. 2.1–2.4: (hum', act', cld')."""
    f = np.zeros_like(act)
    for offset in NEIGHBOURS:
        f |= neighbour(act, offset)
    return hum & ~act, ~act & hum & f, cld | act


def random_numbers(shape, seed: int, step: int, rule: int) -> np.ndarray:
    """uint32 ``U`` in ``[0, 2**16)`` per cell ``[x, y, z]`` for ``rule`` in step ``step``."""
    nx, ny, nz = shape
    nwx = -(-nx // 32)
    words = np.arange(nwx * ny * nz, dtype=np.uint32).reshape(nz, ny, nwx)
    u = np.zeros((nz, ny, nwx * 32), dtype=np.uint32)
    for j in range(PRECISION_BITS):
        ka, kb = stream_key(seed, step, rule, j)
        h = hash_counter(words, ka, kb).astype("<u4")
        bits = np.unpackbits(h.view(np.uint8), axis=-1, bitorder="little")
        u |= bits.astype(np.uint32) << np.uint32(j)
    return np.ascontiguousarray(u[:, :, :nx].transpose(2, 1, 0))


def bernoulli(p, shape, seed: int, step: int, rule: int) -> np.ndarray:
    """bool ``U < T(p)`` per cell; ``p`` a float or an array of ``shape``."""
    return random_numbers(shape, seed, step, rule) < threshold(p)


def advect(a: np.ndarray, shifts: np.ndarray) -> np.ndarray:
    """Eq. 2.8–2.10 with per-layer shifts ``(ny, 2)``: ``out[x, y, z] = a[x - sx[y], y, z - sz[y]]``."""
    out = np.zeros_like(a)
    for y, (sx, sz) in enumerate(np.asarray(shifts, dtype=np.int64).reshape(-1, 2)):
        out[:, y, :] = neighbour(a[:, y, :], (-int(sx), -int(sz)))
    return out


def step(hum, act, cld, *, seed: int, step: int, p_ext=0.0, p_hum=0.0, p_act=0.0, shift=(0, 0)):
    """One whole step (growth → stochastic rules → advection) on bool arrays ``[x, y, z]``.

    ``step`` is the step counter used for the random numbers (``CloudAutomaton.step_count`` before
    the step); ``shift`` is one ``(sx, sz)`` pair or an int array ``(ny, 2)``. Returns (hum, act, cld).
    """
    shape = hum.shape
    hum, act, cld = growth(np.asarray(hum, bool), np.asarray(act, bool), np.asarray(cld, bool))
    cld = cld & ~bernoulli(p_ext, shape, seed, step, RULE_EXT)
    hum = hum | bernoulli(p_hum, shape, seed, step, RULE_HUM)
    act = act | bernoulli(p_act, shape, seed, step, RULE_ACT)
    shifts = np.broadcast_to(np.asarray(shift, dtype=np.int64).reshape(-1, 2), (shape[1], 2))
    return advect(hum, shifts), advect(act, shifts), advect(cld, shifts)
