"""RaymarchCloudSettings: the knobs of the ray-marched clouds, each with what it costs."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import check_bool, check_int, check_num, check_vec
from atmos.plugins.clouds.raymarch.temporal import HISTORY_CLAMP, MOTION_LIMIT
from atmos.plugins.clouds.volume.light import CloudLightSettings

RESOLUTIONS = (1, 2, 4)
MAX_STEPS = 4096
MAX_SUN_STEPS = 16
SUN_SPACING = 0.5        # cells (of the smallest side): the sun march's first step (march.frag sun_transmittance)
SUN_GROWTH = 2.0         # each next sun-march step this many times the last (4 steps reach 7.5 cells)
REFERENCE = dict(resolution=1, jitter=False, reprojection=False, detail_octaves=0, step=0.25, step_growth=0.0,
                 steps=MAX_STEPS, min_transmittance=0.0)
"""The reference configuration (:meth:`RaymarchCloudsPlugin.reference`): every pixel marched, one sample
at the midpoint of every quarter-cell step to the layer's end or the scene depth (at most 4096 samples
in occupied space), no detail noise, jitter, history or early exit; empty-space skipping stays on (it
moves where the steps fall, nothing else). The image the sprites and the real-time settings are
measured against."""


@dataclass(frozen=True)
class RaymarchCloudSettings(CloudLightSettings):
    """How the clouds are marched (all live: a change shows on the next frame).

    ``base_altitude``: world y of the layer's bottom (None: ``CloudSettings.base_altitude``).
    ``steps``: the most density samples per ray (1..4096; the cost is per sample taken, so it caps the
    worst ray). ``step``: the first step's length in cells (of the smallest cell side; 0.05..8;
    halving it doubles the samples of a near cloud). ``step_growth``: the step grows by this share
    of the distance from the camera (step = ``step`` × cell + ``step_growth`` × distance; 0..1;
    0.004 gives 4 m steps at 1 km and 40 m at 10 km, so far clouds cost few samples).
    ``empty_space_skipping``: jump over sprite groups × height bands that hold no density (from the
    simulation's max maps, dilated by one group so the trilinear density is exactly 0 there; free
    where it cannot skip, saves most samples of a sparse sky; the image changes only by where the
    steps fall). ``min_transmittance``: stop a ray once this little light from behind gets through
    (0..0.5; 0 marches to the layer's end; the pixel's alpha is short by at most that much).
    ``jitter``: offset each pixel's first sample by a tiled blue noise of the pixel (:mod:`atmos.blue_noise`),
    fixed in time (turns step banding into fine spatial noise that does not flicker); False: midpoint samples,
    reproducible (tests). ``resolution``: march one pixel of every r × r block (1, 2 or 4; 2 costs a
    quarter of the samples, the frame's jitter moves the marched pixel inside the block).
    ``reprojection``: resolve the low-res samples with the temporal history (r² frames to converge
    with a still camera) instead of a depth-aware upsample of this frame's samples; no effect at
    resolution 1. ``history_clamp`` (0..1): how hard reprojected history is clamped to this frame's 3×3
    samples while the camera moves (0: sharpest, ghosts after motion; 1: no ghost, thin features the
    sparse samples miss flicker; free) and ``motion_limit`` (pixels per frame, > 0): history is mixed
    toward this frame's upsampled samples linearly, gone at this motion (smaller: less smear on fast
    turns, blurrier while moving; free); see :mod:`.temporal`. ``detail_octaves``: noise channels the density is eroded by (0 = off, 1..3; each one
    two more texture fetches per sample), ``detail_scale`` (cells of the smallest side per base-noise tile, 0.5..1e4; 8: billows 2 cells
    across; free; each band fades out where a pixel spans 1/16..1/4 of its tile, so far clouds
    keep their smooth shape instead of aliased stripes and skip the noise reads) and
    ``detail_strength`` (0..1): see ``shaders/clouds/raymarch/detail.glsl``. ``sun_steps``: the sun
    transmittance's own march (0..16): that many steps toward the sun through the actual (trilinear,
    eroded) density, the first half a cell, each next twice the last (4 reach 7.5 cells), then the
    shading volume's T from where they end; 0 = the shading volume's T at the sample alone, which
    holds T at cell centres and blurs the lit surface: toward a 5° sun a dense cumulus came out grey
    with weak rims (reference march vs the path tracer at 192×128: image sum +27.6 % → +18.3 %, rel.
    RMSE 35.7 → 26.0 %, rim/body radiance 0.80 → 0.87, tracer 1.08; the bench's views within 1 point).
    Each step costs one density (and, with detail, one detail) lookup per sample: the reference march
    (no detail) 1.9× its pass time at sun_steps 0 (bench views, 192×128, llvmpipe); with the detail
    on, the lookups the detail's sun correction took before (sunset 1024×768, defaults: the march pass
    0.93× the one before, in one run). Cost of the march at 640×360 on llvmpipe (sunset demo, frame
    minus the frame without the march, one noisy run on shared cores; measured before sun_steps acted
    without the detail): resolution 1 octaves 0 244 ms, octaves 3 sun_steps 0 230 ms, octaves 3
    sun_steps 4 951 ms (the sun steps are the detail's cost); the defaults (resolution 2, reprojection, octaves 3, sun_steps 4)
    218 ms. ``wind``: (x, y, z) m/s the detail noise
    scrolls with when the clouds have no weather (with one, the weather's wind). The
    multiple-scattering octaves ``ms_*``: :class:`~atmos.plugins.clouds.volume.light.CloudLightSettings`.
    ``far_field`` (with a CloudFarFieldPlugin in the scene; else no effect): march on beyond the
    simulated volume through the layer's altitude band out to ``far_distance`` m (1e3..1e6) through a
    volumetric far field (its cover, the same as the 2D far field's and the ground shadows', times a
    vertical profile, eroded by the detail noise: ``shaders/clouds/raymarch/far.glsl``), cross-faded with
    the volume over its edge fade; the 2D far-field pass is then culled. ``far_step_growth`` (0..1): the
    step's growth with distance there (0.02 with 40 m cells: 70 m steps at 2.5 km, 420 m at 20 km;
    halving it about doubles the far samples). Cost of the march pass with the far field over without
    (which draws the 2D far-field pass instead), 640×360 llvmpipe, defaults, one noisy run on shared
    cores: flight from 2.5 km 1.5× (380 vs 258 ms), from 320 m under the deck 2.0× (612 vs 298 ms:
    grazing rays cross tens of km of layer), sunset from the ground 1.3× (273 vs 208 ms).
    ``enabled`` False declares nothing (the pass is culled, allocates nothing).
    """
    base_altitude: float | None = None
    steps: int = 256
    step: float = 0.5
    step_growth: float = 0.004
    empty_space_skipping: bool = True
    min_transmittance: float = 0.01
    jitter: bool = True
    resolution: int = 2
    reprojection: bool = True
    history_clamp: float = HISTORY_CLAMP
    motion_limit: float = MOTION_LIMIT
    detail_octaves: int = 3
    detail_scale: float = 8.0
    detail_strength: float = 1.0
    sun_steps: int = 4
    wind: tuple = (10.0, 0.0, 0.0)
    far_field: bool = True
    far_distance: float = 60000.0
    far_step_growth: float = 0.02
    enabled: bool = True

    def __post_init__(self):
        o = "RaymarchCloudSettings"
        resolution = check_int(o, "resolution", self.resolution, 1, max(RESOLUTIONS))
        if resolution not in RESOLUTIONS:
            raise ValueError(f"{o}.resolution must be 1, 2 or 4 (march one pixel of every r x r block), "
                             f"got {self.resolution!r}")
        self.store(dict(
            base_altitude=check_num(o, "base_altitude", self.base_altitude, optional=True),
            steps=check_int(o, "steps", self.steps, 1, MAX_STEPS),
            step=check_num(o, "step", self.step, 0.05, 8.0),
            step_growth=check_num(o, "step_growth", self.step_growth, 0.0, 1.0),
            empty_space_skipping=check_bool(o, "empty_space_skipping", self.empty_space_skipping),
            min_transmittance=check_num(o, "min_transmittance", self.min_transmittance, 0.0, 0.5),
            jitter=check_bool(o, "jitter", self.jitter),
            resolution=resolution,
            reprojection=check_bool(o, "reprojection", self.reprojection),
            history_clamp=check_num(o, "history_clamp", self.history_clamp, 0.0, 1.0),
            motion_limit=check_num(o, "motion_limit", self.motion_limit, 0.0, 1e4, lo_open=True),
            detail_octaves=check_int(o, "detail_octaves", self.detail_octaves, 0, 3),
            detail_scale=check_num(o, "detail_scale", self.detail_scale, 0.5, 1e4),
            detail_strength=check_num(o, "detail_strength", self.detail_strength, 0.0, 1.0),
            sun_steps=check_int(o, "sun_steps", self.sun_steps, 0, MAX_SUN_STEPS),
            wind=check_vec(o, "wind", self.wind, 3),
            far_field=check_bool(o, "far_field", self.far_field),
            far_distance=check_num(o, "far_distance", self.far_distance, 1e3, 1e6),
            far_step_growth=check_num(o, "far_step_growth", self.far_step_growth, 0.0, 1.0),
            enabled=check_bool(o, "enabled", self.enabled),
            **self.light_checks(),
        ))
