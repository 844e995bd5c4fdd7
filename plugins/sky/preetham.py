"""Preetham, Shirley & Smits (1999) analytic daylight in float64 numpy: the reference the GPU sky is held to.

Perez et al.'s luminance distribution ``F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ)``
(θ: view zenith angle, γ: angle between view and sun) with turbidity-linear coefficients for Y, x and
y; zenith luminance (kcd/m²) and chromaticity from the turbidity T and the sun zenith angle θs;
``value = zenith · F(θ, γ) / F(0, θs)``; then xyY → XYZ → linear sRGB.

Where the model is invalid it is clamped, so that every input gives a finite colour: views below the
horizon use ``cos θ = COS_FLOOR`` (the horizon's value), a sun below the horizon uses ``θs = 90°``
(the night fade of :mod:`atmos.plugins.sky.radiance` takes over there).
"""
from __future__ import annotations

import numpy as np

TURBIDITY_RANGE = (2.0, 10.0)
COS_FLOOR = 0.01      # smallest cos(view zenith) the Perez function sees (B / cos θ stays finite)

# Perez coefficients A..E = slope * T + offset, rows Y, x, y (Preetham et al. 1999, appendix A.2).
PEREZ_SLOPE = np.array([[0.1787, -0.3554, -0.0227, 0.1206, -0.0670],
                        [-0.0193, -0.0665, -0.0004, -0.0641, -0.0033],
                        [-0.0167, -0.0950, -0.0079, -0.0441, -0.0109]])
PEREZ_OFFSET = np.array([[-1.4630, 0.4275, 5.3251, -2.5771, 0.3703],
                         [-0.2592, 0.0008, 0.2125, -0.8989, 0.0452],
                         [-0.2608, 0.0092, 0.2102, -1.6537, 0.0529]])
# zenith chromaticity: [T², T, 1] @ M @ [θs³, θs², θs, 1]
ZENITH_X = np.array([[0.00166, -0.00375, 0.00209, 0.0],
                     [-0.02903, 0.06377, -0.03202, 0.00394],
                     [0.11693, -0.21196, 0.06052, 0.25886]])
ZENITH_Y = np.array([[0.00275, -0.00610, 0.00317, 0.0],
                     [-0.04214, 0.08970, -0.04153, 0.00516],
                     [0.15346, -0.26756, 0.06670, 0.26688]])
XYZ_TO_SRGB = np.array([[3.2406, -1.5372, -0.4986],
                        [-0.9689, 1.8758, 0.0415],
                        [0.0557, -0.2040, 1.0570]])


def check_turbidity(turbidity) -> float:
    """The turbidity as a float, or a ValueError naming the allowed range."""
    try:
        t = float(turbidity)
    except (TypeError, ValueError):
        t = float("nan")
    lo, hi = TURBIDITY_RANGE
    if not lo <= t <= hi:
        raise ValueError(f"turbidity must be a number in [{lo}, {hi}] (2 clear .. 10 hazy); got {turbidity!r}")
    return t


def unit_vectors(v, name: str) -> np.ndarray:
    """(..., 3) float64 unit vectors, or a ValueError (allowed: finite, non-zero 3-vectors)."""
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"{name} must be 3-vectors (shape (..., 3)); got {v!r:.80}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite")
    n = np.sqrt(np.add.reduce(a * a, axis=-1, keepdims=True))     # a norm in ufuncs (per frame)
    if (n == 0).any():
        raise ValueError(f"{name} must have a length > 0; got a zero vector")
    return a / n


def perez_coefficients(turbidity: float) -> np.ndarray:
    """(3, 5): A..E for Y, x, y at ``turbidity``."""
    return PEREZ_SLOPE * turbidity + PEREZ_OFFSET


def perez(coef: np.ndarray, cos_theta, gamma) -> np.ndarray:
    """F(θ, γ) for coefficient rows ``coef`` (3, 5), broadcast over (..., 3) for Y, x, y."""
    a, b, c, d, e = (coef[:, k] for k in range(5))
    ct = np.asarray(cos_theta, np.float64)[..., None]
    g = np.asarray(gamma, np.float64)[..., None]
    return (1.0 + a * np.exp(b / ct)) * (1.0 + c * np.exp(d * g) + e * np.cos(g) ** 2)


def zenith_Yxy(turbidity: float, theta_s: float) -> np.ndarray:
    """(Y, x, y) at the zenith (the row order of the Perez coefficients); Y in kcd/m², ``theta_s`` the
    sun zenith angle in radians (0..π/2)."""
    t = np.array([turbidity ** 2, turbidity, 1.0])
    th = np.array([theta_s ** 3, theta_s ** 2, theta_s, 1.0])
    chi = (4.0 / 9.0 - turbidity / 120.0) * (np.pi - 2.0 * theta_s)
    big_y = (4.0453 * turbidity - 4.9710) * np.tan(chi) - 0.2155 * turbidity + 2.4192
    return np.array([big_y, t @ ZENITH_X @ th, t @ ZENITH_Y @ th])


def angle_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between unit vectors, well conditioned everywhere: 2 atan2(|u − v|, |u + v|). (GPU asin
    and acos can be far less precise than atan: Mesa llvmpipe's asin is off by up to 8e-4.)"""
    return 2.0 * np.arctan2(np.linalg.norm(u - v, axis=-1), np.linalg.norm(u + v, axis=-1))


def sun_zenith_angle(s: np.ndarray) -> float:
    """θs of a unit sun direction, π/2 for a sun on or below the horizon."""
    return float(np.arctan2(np.hypot(s[0], s[2]), s[1])) if s[1] > 0 else 0.5 * np.pi


def xyY_to_srgb(x, y, big_y) -> np.ndarray:
    """(..., 3) linear sRGB (negative parts clipped to 0) from chromaticity and luminance."""
    xyz = np.stack([x / y * big_y, big_y, (1.0 - x - y) / y * big_y], axis=-1)
    return np.maximum(xyz @ XYZ_TO_SRGB.T, 0.0)


def preetham_rgb(view_dir, sun_dir, turbidity) -> np.ndarray:
    """(..., 3) linear sRGB sky radiance in kcd/m² from the Preetham model (clamped as the module says)."""
    t = check_turbidity(turbidity)
    v = unit_vectors(view_dir, "view_dir")
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    theta_s = sun_zenith_angle(s)
    coef = perez_coefficients(t)
    ratio = perez(coef, np.maximum(v[..., 1], COS_FLOOR), angle_between(v, s)) / perez(coef, 1.0, theta_s)
    big_y, x, y = np.moveaxis(zenith_Yxy(t, theta_s) * ratio, -1, 0)
    return xyY_to_srgb(x, y, big_y)
