"""An independent Monte-Carlo volumetric path tracer for small cloud volumes: the reference the
cloud renderers are measured against. It shares no code with them (numpy, float64, vectorised over
paths).

The scene, in the radiometric model of :mod:`atmos.plugins.clouds.light.medium` (physical units):

- the medium: ``density[x, y, z]`` in the documented world layout (:mod:`atmos.plugins.clouds.volume.layout`:
  cell ``(i, j, k)`` centred at ``lo + (i + 0.5, j + 0.5, k + 0.5) * cell``), trilinear between cell
  centres, the edge value held out to the box faces, zero outside the box ``[lo, lo + shape * cell]``;
  extinction ``sigma_t * density`` (1/m), scattering ``albedo * sigma_t * density``;
- the phase function: ``(1 - w) HG(g) + w HG(g2)`` (Henyey-Greenstein lobes, normalised over the sphere);
- the sun: a direction (toward the sun) and an irradiance (RGB, on a plane facing it);
- the environment: radiance ``sky`` from every direction above the horizon (y > 0), ``ground``
  from below; it lights the medium wherever a path leaves the box.

Every order of scattering is followed: free flights by delta tracking against a global majorant,
the sun by next-event estimation with ratio-tracked shadow rays, the environment when a scattered
path leaves the box, Russian roulette once a path's weight is small. The primary rays' transmittance
is ratio-tracked too. :func:`trace` returns the radiance the medium sends back along each ray
(premultiplied: the background is not included; it reaches the eye × ``transmittance``) with the
standard error of every mean.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

ROULETTE_BELOW = 0.05        # paths whose weight falls below this play Russian roulette (survive 1/2)
TINY = 1e-12


@dataclass(frozen=True)
class TraceResult:
    """Per ray: ``radiance`` (n, 3) scattered toward the eye, ``transmittance`` (n,) of the medium
    along it, and the standard errors of both means (``radiance_error`` (n, 3), ``transmittance_error``)."""
    radiance: np.ndarray
    transmittance: np.ndarray
    radiance_error: np.ndarray
    transmittance_error: np.ndarray


class _Medium:
    def __init__(self, density, cell, lo, sigma_t):
        self.rho = np.asarray(density, np.float64)
        if self.rho.ndim != 3 or min(self.rho.shape) < 1 or not np.isfinite(self.rho).all() or (self.rho < 0).any():
            raise ValueError(f"density must be a finite (nx, ny, nz) array >= 0; got shape {self.rho.shape}")
        self.shape = np.array(self.rho.shape)
        self.cell = np.asarray(cell, np.float64).reshape(3)
        self.lo = np.asarray(lo, np.float64).reshape(3)
        if not (self.cell > 0).all() or not np.isfinite(self.cell).all():
            raise ValueError(f"cell must be three finite sizes > 0; got {tuple(self.cell)}")
        self.hi = self.lo + self.shape * self.cell
        self.sigma_t = float(sigma_t)
        self.majorant = self.sigma_t * float(self.rho.max())

    def sigma(self, x: np.ndarray) -> np.ndarray:
        """Extinction (1/m) at world points (n, 3): trilinear between cell centres, edge held."""
        p = np.clip((x - self.lo) / self.cell - 0.5, 0.0, self.shape - 1.0)
        i0 = np.minimum(np.floor(p).astype(np.int64), np.maximum(self.shape - 2, 0))
        f = p - i0
        i1 = np.minimum(i0 + 1, self.shape - 1)
        out = np.zeros(len(x))
        for cx in (0, 1):
            wx = f[:, 0] if cx else 1.0 - f[:, 0]
            ix = i1[:, 0] if cx else i0[:, 0]
            for cy in (0, 1):
                wy = f[:, 1] if cy else 1.0 - f[:, 1]
                iy = i1[:, 1] if cy else i0[:, 1]
                for cz in (0, 1):
                    wz = f[:, 2] if cz else 1.0 - f[:, 2]
                    iz = i1[:, 2] if cz else i0[:, 2]
                    out += wx * wy * wz * self.rho[ix, iy, iz]
        return self.sigma_t * out

    def span(self, x: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(enter, leave) distances of rays x + t d through the box (enter >= 0; leave <= enter: a miss)."""
        safe = np.where(np.abs(d) < TINY, TINY, d)
        t0, t1 = (self.lo - x) / safe, (self.hi - x) / safe
        enter = np.maximum(np.minimum(t0, t1).max(1), 0.0)
        leave = np.maximum(t0, t1).min(1)
        return enter, leave

    def free_flight(self, x, d, rng) -> tuple[np.ndarray, np.ndarray]:
        """Delta tracking from x (inside or on the box) along d: (collided mask, collision points)."""
        n = len(x)
        _, leave = self.span(x, d)
        t = np.zeros(n)
        collided = np.zeros(n, bool)
        todo = np.arange(n) if self.majorant > 0 else np.arange(0)
        while len(todo):
            t[todo] -= np.log1p(-rng.random(len(todo))) / self.majorant
            inside = t[todo] < leave[todo]
            todo = todo[inside]
            if not len(todo):
                break
            s = self.sigma(x[todo] + t[todo, None] * d[todo])
            real = rng.random(len(todo)) * self.majorant < s
            collided[todo[real]] = True
            todo = todo[~real]
        return collided, x + np.where(collided, t, 0.0)[:, None] * d

    def transmittance(self, x, d, rng, stop: np.ndarray | None = None) -> np.ndarray:
        """Ratio tracking from x along d to the box's far face (or ``stop``): an unbiased estimate of
        exp(-optical depth) per ray."""
        enter, leave = self.span(x, d)
        if stop is not None:
            leave = np.minimum(leave, stop)
        T = np.ones(len(x))
        t = enter.copy()
        todo = np.flatnonzero(leave > enter) if self.majorant > 0 else np.arange(0)
        while len(todo):
            t[todo] -= np.log1p(-rng.random(len(todo))) / self.majorant
            todo = todo[t[todo] < leave[todo]]
            if not len(todo):
                break
            T[todo] *= 1.0 - self.sigma(x[todo] + t[todo, None] * d[todo]) / self.majorant
            low = T[todo] < 1e-3                  # roulette on nearly opaque shadow rays (unbiased)
            if low.any():
                k = todo[low]
                keep = rng.random(len(k)) < 0.5
                T[k] = np.where(keep, T[k] * 2.0, 0.0)
                todo = np.concatenate([todo[~low], k[keep]])
        return T


def _hg(cos, g):
    return (1.0 - g * g) / (4.0 * math.pi * np.maximum(1.0 + g * g - 2.0 * g * cos, TINY) ** 1.5)


def phase(cos, g: float, g2: float = 0.0, w: float = 0.0):
    """The two-lobe Henyey-Greenstein phase function (1/sr) at the cosine of the scattering angle."""
    cos = np.asarray(cos, np.float64)
    return (1.0 - w) * _hg(cos, g) + w * _hg(cos, g2)


def _sample_hg(g: np.ndarray, xi: np.ndarray) -> np.ndarray:
    iso = np.abs(g) < 1e-4
    gs = np.where(iso, 0.5, g)
    s = (1.0 - gs * gs) / (1.0 - gs + 2.0 * gs * xi)
    cos = (1.0 + gs * gs - s * s) / (2.0 * gs)
    return np.clip(np.where(iso, 1.0 - 2.0 * xi, cos), -1.0, 1.0)


def _scatter(d, g, g2, w, rng) -> np.ndarray:
    n = len(d)
    lobe = np.where(rng.random(n) < w, g2, g)
    cos = _sample_hg(lobe, rng.random(n))
    sin = np.sqrt(np.maximum(0.0, 1.0 - cos * cos))
    phi = 2.0 * math.pi * rng.random(n)
    helper = np.where(np.abs(d[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    a = np.cross(d, helper)
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b = np.cross(d, a)
    out = cos[:, None] * d + (sin * np.cos(phi))[:, None] * a + (sin * np.sin(phi))[:, None] * b
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def _color(c, what):
    c = np.asarray(c, np.float64)
    c = np.broadcast_to(c, (3,)) if c.ndim == 0 else c.reshape(3)
    if not np.isfinite(c).all() or (c < 0).any():
        raise ValueError(f"{what} must be 3 finite numbers >= 0 (RGB); got {c!r}")
    return c


def trace(density, cell, lo, origins, directions, *, sigma_t: float, albedo: float = 1.0, g: float = 0.0,
          g2: float = 0.0, w: float = 0.0, sun_dir=(0.0, 1.0, 0.0), sun_irradiance=(0.0, 0.0, 0.0),
          sky=(0.0, 0.0, 0.0), ground=(0.0, 0.0, 0.0), samples: int = 16, max_order: int | None = None,
          rng=None, batch: int = 1 << 18) -> TraceResult:
    """Path-trace rays ``origins`` (n, 3) + t ``directions`` (n, 3) through the medium (module docstring)
    with ``samples`` paths each. ``max_order``: count only light scattered at most that many times
    (None: all orders; 1: single scattering). ``rng``: a numpy Generator (None: seeded 0)."""
    medium = _Medium(density, cell, lo, sigma_t)
    if not 0.0 <= albedo <= 1.0 or not 0.0 <= w <= 1.0 or not all(-1.0 < v < 1.0 for v in (g, g2)):
        raise ValueError(f"need 0 <= albedo <= 1, 0 <= w <= 1, -1 < g, g2 < 1; got {albedo}, {w}, {g}, {g2}")
    if not (medium.sigma_t >= 0 and math.isfinite(medium.sigma_t)):
        raise ValueError(f"sigma_t must be finite and >= 0 (1/m at density 1); got {sigma_t!r}")
    sun = np.asarray(sun_dir, np.float64).reshape(3)
    sun = sun / np.linalg.norm(sun)
    e_sun, sky, ground = _color(sun_irradiance, "sun_irradiance"), _color(sky, "sky"), _color(ground, "ground")
    rng = rng if rng is not None else np.random.default_rng(0)
    o = np.asarray(origins, np.float64).reshape(-1, 3)
    d = np.asarray(directions, np.float64).reshape(-1, 3)
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    n = len(o)
    radiance, radiance2 = np.zeros((n, 3)), np.zeros((n, 3))
    trans, trans2 = np.zeros(n), np.zeros(n)
    ray = np.repeat(np.arange(n), samples)
    for start in range(0, len(ray), batch):
        r = ray[start:start + batch]
        L, T = _paths(medium, o[r], d[r], albedo, g, g2, w, sun, e_sun, sky, ground, max_order, rng)
        for acc, acc2, v in ((radiance, radiance2, L), (trans, trans2, T)):
            np.add.at(acc, r, v)
            np.add.at(acc2, r, v * v)
    mean_l, mean_t = radiance / samples, trans / samples
    var_l = np.maximum(radiance2 / samples - mean_l ** 2, 0.0)
    var_t = np.maximum(trans2 / samples - mean_t ** 2, 0.0)
    denom = max(samples - 1, 1)
    return TraceResult(mean_l, mean_t, np.sqrt(var_l / denom), np.sqrt(var_t / denom))


def _paths(medium, o, d, albedo, g, g2, w, sun, e_sun, sky, ground, max_order, rng):
    n = len(o)
    L = np.zeros((n, 3))
    enter, leave = medium.span(o, d)
    hit = leave > enter
    T = medium.transmittance(o, d, rng)
    idx = np.flatnonzero(hit)
    x = o[idx] + enter[idx, None] * d[idx]
    dirs = d[idx]
    weight = np.ones(len(idx))
    order = 0
    while len(idx):
        collided, x = medium.free_flight(x, dirs, rng)
        if order > 0:
            out = ~collided
            env = np.where(dirs[out, 1:2] > 0.0, sky, ground)
            np.add.at(L, idx[out], weight[out, None] * env)
        idx, x, dirs, weight = idx[collided], x[collided], dirs[collided], weight[collided] * albedo
        order += 1
        if not len(idx):
            break
        if e_sun.any():
            ts = medium.transmittance(x, np.broadcast_to(sun, x.shape), rng)
            p = phase(dirs @ sun, g, g2, w)
            np.add.at(L, idx, (weight * p * ts)[:, None] * e_sun)
        if max_order is not None and order >= max_order:
            if order == max_order:           # escapes after the last counted scattering still count
                dirs = _scatter(dirs, g, g2, w, rng)
                tt = medium.transmittance(x, dirs, rng)
                env = np.where(dirs[:, 1:2] > 0.0, sky, ground)
                np.add.at(L, idx, (weight * tt)[:, None] * env)
            break
        dirs = _scatter(dirs, g, g2, w, rng)
        low = weight < ROULETTE_BELOW
        if low.any():
            survive = rng.random(int(low.sum())) < 0.5
            keep = np.ones(len(idx), bool)
            keep[np.flatnonzero(low)[~survive]] = False
            weight = np.where(low, weight * 2.0, weight)
            idx, x, dirs, weight = idx[keep], x[keep], dirs[keep], weight[keep]
    return L, T


def camera_rays(position, forward, up, fov_y_deg: float, size) -> tuple[np.ndarray, np.ndarray]:
    """(origins, directions) of a pinhole camera's pixel centres, (h * w, 3) each, first row at the top."""
    width, height = size
    f = np.asarray(forward, np.float64)
    f = f / np.linalg.norm(f)
    r = np.cross(f, np.asarray(up, np.float64))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    th = math.tan(math.radians(fov_y_deg) / 2.0)
    ys = (1.0 - 2.0 * (np.arange(height) + 0.5) / height) * th
    xs = (2.0 * (np.arange(width) + 0.5) / width - 1.0) * th * width / height
    dirs = f + xs[None, :, None] * r + ys[:, None, None] * u
    dirs = dirs.reshape(-1, 3)
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return np.broadcast_to(np.asarray(position, np.float64), dirs.shape).copy(), dirs
