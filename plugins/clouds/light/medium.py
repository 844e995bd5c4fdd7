"""The radiometric model every cloud renderer draws, in physical units.

The medium (``CloudSettings``): density ``rho(x)`` from the volume ``[x, y, z]`` placed by
:mod:`atmos.plugins.clouds.volume.layout`, trilinear between cell centres; extinction ``sigma_t * rho``
(``sigma_t`` in 1/m at density 1; cells need not be cubes: optical depth is measured along world
paths, so the thesis's per-cell sigma is derived, :func:`cell_sigma`); scattering
``albedo * sigma_t * rho``; phase function ``settings.phase`` (:class:`atmos.phase.Phase`)
(Henyey-Greenstein lobes normalised over the sphere, 1/sr).

The light: sun irradiance ``E = sun_intensity * Sun.color`` (on a plane facing the sun; the colour
already carries its path through the atmosphere and is 0 below the horizon; the default 4 pi makes
isotropic single scattering of a unit colour equal to the colour, the old ``sun x T`` model); sky
radiance ``L_sky = sky_intensity * Sun.ambient`` from every direction above the horizon; the ground
below a Lambertian of albedo ``rho_g`` (the scene's ground, :class:`atmos.lighting.GroundSurface`, else
``ground_albedo``) lit by both, radiance ``rho_g * (E * max(sun_y, 0) * G / pi + L_sky)``, ``G`` the
ground's mean sun transmittance through the clouds (their shadow on it: :mod:`.ground`; 1 without).
:func:`environment` gives the three; :mod:`atmos.plugins.clouds.light.path_tracer` renders exactly
this scene (all orders), the real-time renderers approximate it (``clouds/volume/volume.glsl``):

    source per unit extinction J = albedo * (E * (sum_i b^i p(cos; c^i g) P_i(T) + beta L_field)
                                             + w_sky L_sky + w_ground L_ground)

with ``T`` the transmittance toward the sun and ``p`` the phase at the angle between the view ray and
the sun (per pixel). The sun's light splits in two. What stays forward: octaves ``i < 4`` after
Wrenninge (b: ``ms_contribution``, c: ``ms_eccentricity``), each over the light that reached the point
forward-scattered ``i`` times on its way (:func:`octave_transmittances`): the count is Poisson with
mean ``x = (1 - a) tau`` (``tau = -ln T``; a: ``ms_attenuation``, the share of scatterings that turn
light aside, near ``1 - g_mean``), so ``P = (T, T x, T x²/2, T^a - those)``, the last all higher counts.
Light only forward-scattered once has a path behind it: the thin lit rim of a cloud holds little of it
(its "powder" darkening), and deep in the cloud it falls as ``T^a``. What is turned aside: the
diffusion field (:mod:`atmos.plugins.clouds.light.diffusion`, weight beta: ``ms_diffusion`` scaled by
``sqrt(a / a_0)``, :func:`field_weight`), a P1 solve of the scattered fluence whose radiance ``L_field`` is
diffuse and runs with the flux.
``tau_up``/``tau_down`` (straight up and down to the volume's faces) come from the light volume's
columns, computed once per texture set (:mod:`atmos.plugins.clouds.light.columns`).
Sky and ground light: the diffusion solution between a slab's two lit faces (:func:`ambient_weights`):
each face's share ``sinh(kappa (tau_other + z)) / sinh(kappa D)`` with the extrapolation length
``z = 2 / (3 (1 − albedo g_mean))`` and ``kappa = sqrt(3 (1 − albedo)(1 − albedo g_mean))``, the linear
``(tau_other + z) / D`` at albedo 1 (deep in a cloud the light is the faces' mean, near a face that
face's; a white furnace, equal sky and ground at albedo 1, gives exactly ``J = L`` at any depth; below
albedo 1 diffuse light dies with depth), plus where the column is thin the phase's forward share
``g_mean ray_y`` (looking up at a thin base sees sky light scattered forward). No fitted constant dims
it. The octaves follow the medium (:func:`octave_parameters`: a and c from the phase unless set, the
albedo per forward scattering); b and beta are fitted to the path tracer
(``benchmarks/bench_cloud_light.py --fit-grid``).
"""
from __future__ import annotations

import math

import numpy as np

from atmos.phase import Phase, phase

OCTAVES = 4


def cell_sigma(sigma_t: float, cell, direction) -> float:
    """Extinction per unit index-space length along ``direction`` (world) for cells of size ``cell``:
    what grid-space shading (the shear-warp, stepping in cells) multiplies by."""
    cell = np.asarray(cell, np.float64)
    u = np.asarray(direction, np.float64) / cell
    n = np.linalg.norm(u)
    if not (n > 0 and np.isfinite(n)):
        return float(sigma_t * np.cbrt(cell.prod()))
    return float(sigma_t * np.linalg.norm(u / n * cell))


def ground_parts(settings, sun_color, sky, sun_dir, albedo=None) -> tuple[np.ndarray, np.ndarray]:
    """(sunlit, sky-lit) parts of the ground's radiance as float64 RGB: ``rho_g E max(sun_y, 0) / pi`` and
    ``rho_g L_sky`` (``albedo``: the scene ground's RGB; None: the medium's ``ground_albedo``); the radiance
    is ``sky-lit + G sunlit`` at the ground's mean sun transmittance ``G``."""
    rho = settings.ground_albedo if albedo is None else np.asarray(albedo, np.float64)
    s = np.asarray(sun_dir, np.float64)
    up = max(float(s[1] / math.sqrt(s.dot(s))), 0.0)   # np.linalg.norm's own formula (1-D float64), without its overhead
    e = settings.sun_intensity * np.asarray(sun_color, np.float64)
    return rho * e * up / math.pi, rho * settings.sky_intensity * np.asarray(sky, np.float64)


def environment(settings, sun_color, sky, sun_dir, albedo=None, ground_sun: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sun irradiance E, sky radiance, ground radiance) as float64 RGB for a ``CloudSettings``, the
    ground of ``albedo`` (None: ``settings.ground_albedo``) at mean sun transmittance ``ground_sun``."""
    e = settings.sun_intensity * np.asarray(sun_color, np.float64)
    lit, sky_lit = ground_parts(settings, sun_color, sky, sun_dir, albedo)
    return e, settings.sky_intensity * np.asarray(sky, np.float64), sky_lit + ground_sun * lit


def octave_transmittances(T, a: float) -> np.ndarray:
    """(..., 4): the octaves' sun transmittances P_i of the module docstring at transmittance ``T``:
    light that reached the point forward-scattered k times on its way, k Poisson with mean
    x = (1 - a) tau (tau = -ln T; ``a`` the share of scatterings that turn light aside), (T, T x, T x²/2)
    for k = 0, 1, 2 and the rest of T^a (all k) for the higher counts (``shaders/lib/octaves.glsl``)."""
    T = np.clip(np.asarray(T, np.float64), 0.0, 1.0)
    x = -(1.0 - a) * np.log(np.maximum(T, 1e-30))
    low = [T, T * x, 0.5 * T * x * x]
    return np.stack([*low, np.maximum(T ** a - sum(low), 0.0)], -1)


FORWARD_SCALE = 1.0      # k_f: the forward share 1 - a = k_f g_mean where ms_attenuation is None (bench_cloud_light --fit-grid)
ECCENTRICITY_SCALE = 1.0  # k_c: the octaves' eccentricity c = k_c g where ms_eccentricity is None


def phase_octaves(phase, scales=None) -> tuple[float, float]:
    """(a, c) that follow the phase (:class:`atmos.phase.Phase`): the forward share 1 - a = k_f g_mean (the
    similarity relation's share that stays forward), c = k_c g (octave i's lobe c^i g near g^(i+1): i forward
    scatterings, then one toward the eye); ``scales``: (k_f, k_c), None: FORWARD_SCALE, ECCENTRICITY_SCALE."""
    k_f, k_c = (FORWARD_SCALE, ECCENTRICITY_SCALE) if scales is None else scales
    return 1.0 - min(k_f * max(phase.mean_cosine, 0.0), 1.0), min(k_c * max(phase.g, 0.0), 1.0)


def octave_parameters(octaves, settings) -> tuple[float, float, float]:
    """(a, b, c) the renderers' octaves take (``volume.glsl`` ``ms_octaves``) for the medium ``settings``
    (a CloudSettings) from a CloudLightSettings' ``octaves`` (a, b, c), a or c None: :func:`phase_octaves`'.
    Light that stays forward keeps ``albedo`` of itself per scattering: the Poisson count of k forward
    scatterings then weighs albedo^k, which is the same Poisson law with the forward share albedo (1 - a),
    so a becomes 1 - albedo (1 - a)."""
    a, b, c = octaves
    if a is None or c is None:
        derived = phase_octaves(settings.phase)
        a, c = derived[0] if a is None else a, derived[1] if c is None else c
    return 1.0 - float(settings.albedo) * (1.0 - float(a)), float(b), float(c)


FIELD_REFERENCE_A = 1.0 - Phase().mean_cosine   # a_0: the default phase's 1 - g_mean (0.265), where beta was fitted
FIELD_POWER = 0.5           # the field's weight goes as (a / a_0)^FIELD_POWER (0, 1/2 and 1 measured on the grid)


def field_weight(beta: float, octaves, settings) -> float:
    """The diffusion field's weight in J for the weight ``beta`` (``ms_diffusion``), the CloudLightSettings'
    ``octaves`` and the medium ``settings``: ``beta sqrt(a / a_0)``, a the share of scatterings that turn
    light aside (``ms_attenuation``, or 1 - g_mean from the phase; before the albedo, since absorbed light
    is not turned aside). A strongly forward phase turns less light into the field: at g 0.9 beta alone
    left side views +17..+42 % too bright against the path tracer (``bench_cloud_light.py --grid``). The
    default phase keeps beta exactly. 0 stays 0 (no field)."""
    beta = float(beta)
    if beta <= 0.0:
        return 0.0
    a = octaves[0]
    if a is None:
        a = phase_octaves(settings.phase)[0]
    return beta * (max(float(a), 0.0) / FIELD_REFERENCE_A) ** FIELD_POWER


def octave_weights(T, a: float, b: float) -> np.ndarray:
    """(..., 4): ``b^i P_i(T)`` of the module docstring."""
    return octave_transmittances(T, a) * b ** np.arange(OCTAVES)


def ambient_weights(tau_up, tau_down, g_mean: float, albedo: float, ray_y) -> np.ndarray:
    """(..., 2): the shares (w_sky, w_ground) of J's sky and ground part, ``albedo (w_sky L_sky + w_ground
    L_ground)``, at column optical depths ``tau_up``/``tau_down`` (``volume.glsl`` ambient_source): each
    face's share of the diffusion solution between a slab's two lit faces, ``sinh(kappa (tau_other + z)) /
    sinh(kappa D)``, ``D = tau_up + tau_down + 2 z``, extrapolation length ``z = 2 / (3 (1 - albedo g_mean))``,
    ``kappa = sqrt(3 (1 - albedo) (1 - albedo g_mean))`` how fast diffuse light dies per optical depth
    (at albedo 1 the limit ``(tau_other + z) / D``: equal sky and ground give exactly ``J = L``); where the
    column is thin, ``g_mean ray_y exp(-(tau_up + tau_down) / 2z)`` / 2 of their sum moves from the
    ground's share to the sky's (looking up at a thin base sees sky light scattered forward), each share
    kept within [0, sum]."""
    up, down = np.asarray(tau_up, np.float64), np.asarray(tau_down, np.float64)
    z = 2.0 / (3.0 * (1.0 - min(albedo * g_mean, 0.99)))
    d = up + down + 2.0 * z
    kappa = math.sqrt(max(3.0 * (1.0 - albedo) * (1.0 - albedo * g_mean), 0.0))

    def share(x):
        y = kappa * d
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            ratio = np.exp(kappa * x - y) * -np.expm1(-2.0 * kappa * x) / -np.expm1(-2.0 * y)
        return np.where(y < 1e-3, x / d, ratio)

    w = np.stack(np.broadcast_arrays(share(down + z), share(up + z)), -1)
    s = w.sum(-1)
    f = 0.5 * s * g_mean * np.asarray(ray_y, np.float64) * np.exp(-(up + down) / (2.0 * z))
    return np.clip(w + np.stack([f, -f], -1), 0.0, s[..., None])


def source_reference(settings, render, T, tau_up, tau_down, cos, ray_y, sun_color, sky, sun_dir,
                     diffusion=None, *, octaves=None, sun_colors=None, albedo=None, ground_sun: float = 1.0) -> np.ndarray:
    """float64 (n, 3): J of the module docstring at points with transmittance ``T`` (or, given
    ``octaves`` (n, 4), those as the octaves' sun transmittances: the far fields' by rank), column optical
    depths ``tau_up``/``tau_down``, view/sun cosine ``cos`` and view ray y ``ray_y`` (``render``:
    the CloudRenderSettings or RaymarchCloudSettings); ``diffusion``: the diffusion field's radiance
    there (:func:`atmos.plugins.clouds.light.diffusion.diffusion_radiance`, unit irradiance), added with the weight
    :func:`field_weight` of ``render.ms_diffusion`` (None: no field); ``sun_colors`` (n, 3): the sun's colour at each point
    (None: ``sun_color``, which the ground's light takes in any case); ``albedo``, ``ground_sun``: the
    ground's (:func:`environment`)."""
    e, l_sky, l_ground = environment(settings, sun_color, sky, sun_dir, albedo, ground_sun)
    if sun_colors is not None:
        e = settings.sun_intensity * np.asarray(sun_colors, np.float64)
    tau_up, tau_down = np.asarray(tau_up, np.float64), np.asarray(tau_down, np.float64)
    a, b, c = octave_parameters(render.octaves, settings)
    g_mean = settings.phase.mean_cosine
    w = octave_weights(T, a, b) if octaves is None else np.asarray(octaves, np.float64) * b ** np.arange(OCTAVES)
    sun = sum(w[..., i] * phase(cos, settings.phase.g * c ** i, settings.phase.g2 * c ** i, settings.phase.w)
              for i in range(OCTAVES))
    if diffusion is not None:
        sun = sun + field_weight(render.ms_diffusion, render.octaves, settings) * np.asarray(diffusion, np.float64)
    w = ambient_weights(tau_up, tau_down, g_mean, settings.albedo, ray_y)
    amb = w[..., :1] * l_sky + w[..., 1:] * l_ground
    return settings.albedo * (sun[..., None] * e + amb)
