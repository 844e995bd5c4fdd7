"""The soft particle every cloud sprite is drawn with (``sprite.vert``/``sprite.frag``, float64 here).

A sprite stands for a block's mass: its cells' densities, each spread around its centre by the
trilinear hat the ray march samples (variance 1/6 cell² per axis), widened to the quadratic B-spline
(the hat convolved with one cell, variance 1/4: a Gaussian of 1/6 leaves a ±7 % ripple of the grid
in the optical depth, visible as stripes in thin cloud, one of 1/4 under 1 %), so on the screen the mass covers a Gaussian footprint
with the covariance ``Σ`` of that mass projected on the screen axes (camera right, up; in sprite
radii: :func:`footprint`). It is an ellipse for non-cubic cells (flat cells seen from the side), so
neither the grid shows along the long axis nor the cloud blurs along the short one. The profile is
that Gaussian cut to 0 at the iso-line whose long semi-axis is the radius, ``p = (exp(−Q/2) −
exp(−k)) / (1 − exp(−k))``, ``Q = xᵀ Σ⁻¹ x``, ``k = 1 / (2 λ_max)``; its integral is ``2π sqrt(det Σ)
radius² (1 − e^−k − k e^−k) / (1 − e^−k)``, so the centre optical depth :func:`centre_tau` spreads
the block's optical depth over the screen exactly.

The screen axes are the perspective's Jacobian at the sprite (:func:`screen_axes`, as EWA splatting):
``right − m_x forward``, ``up − m_y forward`` with ``m`` the sprite's view-space x/z, y/z. Off-axis a
blob's depth projects sideways, so its footprint and its neighbours' spacing stretch radially by up to
``sqrt(1 + |m|²)``; the plain right/up footprint was too narrow there by that factor (cos θ of the
angle off-axis), which in the weather demo's near clouds 30–40° off-axis showed the grid as stripes
one cell apart (a ±5–7 % ripple of the optical depth instead of ±1.4 %). The point is drawn that
much larger, and the footprint is in units of its half side.
"""
from __future__ import annotations

import math

import numpy as np

CELL_VARIANCE = 0.25         # per axis (cells²): the quadratic B-spline's (the trilinear hat's is 1/6)
MIN_FALLOFF = 1e-2           # k this small is the 1 − Q/2k ellipse, the profile's limit
MAX_OFF_AXIS = 4.0           # |x/z|, |y/z| the Jacobian takes (76°; behind the camera: no degenerate axes)


def screen_axes(offset, right, up, near) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(axis x (n, 3), axis y (n, 3), stretch (n,)) of sprites at ``offset`` (n, 3) from the camera whose
    right and up are ``right``, ``up``: the perspective's Jacobian rows ``right − m_x forward``, ``up −
    m_y forward`` divided by the stretch ``sqrt(1 + |m|²)`` (the point's half side in radii); ``m``
    is the view x/z, y/z, z at least ``near``, each within ±MAX_OFF_AXIS."""
    offset = np.asarray(offset, np.float64)
    r, u = np.asarray(right, np.float64), np.asarray(up, np.float64)
    f = np.cross(u, r)
    m = np.clip(np.stack([offset @ r, offset @ u], -1) / np.maximum(offset @ f, near)[:, None],
                -MAX_OFF_AXIS, MAX_OFF_AXIS)
    stretch = np.sqrt(1.0 + (m * m).sum(-1))
    return ((r - m[:, :1] * f) / stretch[:, None], (u - m[:, 1:] * f) / stretch[:, None], stretch)


def footprint(cells_var, cell, radius, right, up) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(conic (n, 3): Σ⁻¹ as xx, xy, yy; k (n,); det Σ (n,)) of blocks whose cell centres have the
    variance ``cells_var`` (n, 3, cells²), for cells of size ``cell`` (m), sprites of ``radius``
    (n,, m) and the screen axes ``right``, ``up`` ((3,) or per sprite (n, 3): :func:`screen_axes`)."""
    v = (np.asarray(cells_var, np.float64) + CELL_VARIANCE) * np.asarray(cell, np.float64) ** 2
    v = v / np.asarray(radius, np.float64)[:, None] ** 2
    r, u = np.asarray(right, np.float64), np.asarray(up, np.float64)
    xx, xy, yy = (v * r * r).sum(-1), (v * r * u).sum(-1), (v * u * u).sum(-1)
    det = xx * yy - xy * xy
    longest = 0.5 * (xx + yy) + np.sqrt(0.25 * (xx - yy) ** 2 + xy * xy)
    return np.stack([yy, -xy, xx], -1) / det[:, None], np.maximum(0.5 / longest, MIN_FALLOFF), det


def profile(x, y, conic, k) -> np.ndarray:
    """The profile at screen offsets ``x``, ``y`` (in radii; 1 at the centre, 0 past the cut)."""
    e = np.exp(-np.asarray(k, np.float64))
    form = conic[..., 0] * x * x + 2.0 * conic[..., 1] * x * y + conic[..., 2] * y * y
    return np.maximum(np.exp(-0.5 * form) - e, 0.0) / (1.0 - e)


def centre_tau(optical_area, radius, det, k, stretch=1.0) -> np.ndarray:
    """Centre optical depth of a sprite whose profile integrates to ``optical_area`` (m²: sigma_t ×
    V × density summed) across the view ray; ``det``, ``k`` of its footprint in half sides of
    ``stretch`` radii (the screen-parallel plane's area is ``stretch`` × the ray-normal one's)."""
    k = np.asarray(k, np.float64)
    e = np.exp(-k)
    return optical_area * (1.0 - e) / (2.0 * math.pi * np.sqrt(det) * np.asarray(radius, np.float64) ** 2
                                       * np.asarray(stretch, np.float64) * (1.0 - e - k * e))
