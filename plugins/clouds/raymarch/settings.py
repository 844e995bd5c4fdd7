"""RaymarchCloudSettings: the knobs of the ray-marched clouds, each with what it costs."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import bool_field, int_field, num_field, type_field, vec_field
from atmos.plugins.clouds.volume.shape import CLOUD_TYPES, CloudTypeMap
from atmos.plugins.clouds.raymarch.temporal import HISTORY_CLAMP, MOTION_LIMIT
from atmos.plugins.clouds.volume.light import CloudLightSettings

RESOLUTIONS = (1, 2, 4)
MAX_STEPS = 4096
MAX_SUN_STEPS = 16
SUN_SPACING = 0.5        # cells (of the smallest side): the sun march's first step (march.glsl sun_transmittance)
SUN_GROWTH = 2.0         # each next sun-march step this many times the last (4 steps reach 7.5 cells)
REFERENCE = dict(resolution=1, jitter=False, reprojection=False, detail_octaves=0, step=0.25, step_growth=0.0,
                 steps=MAX_STEPS, min_transmittance=0.0, cloud_type=None, type_map=None)
"""The reference configuration (:meth:`RaymarchCloudsPlugin.reference`): every pixel marched, one sample
at the midpoint of every quarter-cell step to the layer's end or the scene depth (at most 4096 samples
in occupied space), no detail noise, jitter, history, early exit or cloud type (the simulation's own shape, as the sprites draw it); empty-space skipping stays on (it
moves where the steps fall, nothing else). The image the sprites and the real-time settings are
measured against."""


@dataclass(frozen=True)
class RaymarchCloudSettings(CloudLightSettings):
    """How the clouds are marched, each field with what it costs (all live: a change shows on the next
    frame). The multiple-scattering octaves ``ms_*`` come first, inherited from
    :class:`~atmos.plugins.clouds.volume.light.CloudLightSettings` (shared with the sprites).

    Checked by hand after the rules listed below: ``resolution`` must be 1, 2 or 4 (its 1..4 lets 3 by).
    """
    base_altitude: float | None = num_field(None, doc="world y of the layer's bottom (None: "
                                            "``CloudSettings.base_altitude``)", optional=True)
    steps: int = int_field(256, 1, MAX_STEPS, "the most density samples per ray (the cost is per sample taken, "
                           "so it caps the worst ray)")
    step: float = num_field(0.5, 0.05, 8.0, "the first step's length in cells (of the smallest cell side; "
                            "halving it doubles the samples of a near cloud)")
    step_growth: float = num_field(0.004, 0.0, 1.0, "the step grows by this share of the distance from the "
                                   "camera (step = ``step`` × cell + ``step_growth`` × distance; 0.004 gives 4 m "
                                   "steps at 1 km and 40 m at 10 km, so far clouds cost few samples)")
    empty_space_skipping: bool = bool_field(True, "jump over sprite groups × height bands that hold no density "
                                            "(from the simulation's max maps, dilated by one group so the "
                                            "trilinear density is exactly 0 there; free where it cannot skip, "
                                            "saves most samples of a sparse sky; the image changes only by where "
                                            "the steps fall)")
    min_transmittance: float = num_field(0.01, 0.0, 0.5, "stop a ray once this little light from behind gets "
                                         "through (0 marches to the layer's end; the pixel's alpha is short by at "
                                         "most that much)")
    jitter: bool = bool_field(True, "offset each pixel's first sample by a tiled blue noise of the pixel "
                              "(:mod:`atmos.blue_noise`; turns step banding into fine noise); with the temporal "
                              "resolve (resolution > 1, reprojection) turned by the golden ratio every 2 r² "
                              "frames and averaged (a still picture converges to the mean over offsets), "
                              "else fixed in time; False: midpoint samples, reproducible (tests)")
    resolution: int = int_field(2, 1, max(RESOLUTIONS), "march one pixel of every r × r block (1, 2 or 4; 2 "
                                "costs a quarter of the samples, the frame's jitter moves the marched pixel "
                                "inside the block)")
    reprojection: bool = bool_field(True, "resolve the low-res samples with the temporal history (r² frames to "
                                    "converge with a still camera) instead of a depth-aware upsample of this "
                                    "frame's samples; no effect at resolution 1")
    history_clamp: float = num_field(HISTORY_CLAMP, 0.0, 1.0, "how hard reprojected history is clamped to this "
                                     "frame's 3×3 samples while the camera moves (0: sharpest, ghosts after "
                                     "motion; 1: no ghost, thin features the sparse samples miss flicker; free; "
                                     ":mod:`.temporal`)")
    motion_limit: float = num_field(MOTION_LIMIT, 0.0, 1e4, "pixels per frame: history is mixed toward this "
                                    "frame's upsampled samples linearly, gone at this motion (smaller: less smear "
                                    "on fast turns, blurrier while moving; free; :mod:`.temporal`)", lo_open=True)
    cloud_type: float | None = num_field(CLOUD_TYPES["cumulus"], 0.0, 1.0, "the clouds' vertical shape "
                                         "(Nubis' cloud type, :mod:`.shape`): 0 stratus (a thin flat sheet low in "
                                         "the layer), 0.5 cumulus (flat bases, round tops at about two thirds of the "
                                         "layer), 1 congestus (towers to the layer's top, widening under it), "
                                         "between them a blend (``CLOUD_TYPES`` names them); each simulated column's "
                                         "mean density sets how much of the type's height profile it fills, and the "
                                         "detail noise erodes wherever the density is below the body's, through the "
                                         "volume. The same type everywhere (the far field too). None: the "
                                         "simulation's own vertical shape (what the sprites draw). Cost: the column's "
                                         "texture read in place of the density's per sample; skipping then skips only "
                                         "whole empty columns; the sun march takes 2 more (long) steps in place of "
                                         "the shading volume, which holds the simulation's own shape",
                                         optional=True)
    type_map: CloudTypeMap | None = type_field(None, CloudTypeMap, "cloud types by region: a "
                                               ":class:`~.shape.CloudTypeMap` of types over the ground "
                                               "(world metres), read bilinearly at every density sample and "
                                               "in the far field, in place of ``cloud_type`` (typed even when "
                                               "that is None); None: ``cloud_type`` everywhere. Cost: one "
                                               "filtered fetch per density sample", optional=True)
    detail_octaves: int = int_field(3, 0, 3, "noise channels the density is eroded by (0 = off; each one two "
                                    "more texture fetches per sample; ``shaders/clouds/raymarch/detail.glsl``)")
    detail_scale: float = num_field(8.0, 0.5, 1e4, "cells of the smallest side per base-noise tile (8: billows "
                                    "2 cells across; free; each band fades out where a pixel spans 1/16..1/4 of "
                                    "its tile, so far clouds keep their smooth shape instead of aliased stripes "
                                    "and skip the noise reads)")
    detail_strength: float = num_field(1.0, 0.0, 1.0, "how hard the detail noise reshapes the density (0: not "
                                       "at all; ``shaders/clouds/raymarch/detail.glsl``)")
    sun_steps: int = int_field(4, 0, MAX_SUN_STEPS, "the sun transmittance's own march: that many steps toward "
                               "the sun through the actual (trilinear, eroded) density, the first half a cell, "
                               "each next twice the last (4 reach 7.5 cells), then the shading volume's T from "
                               "where they end; 0 = the shading volume's T at the sample alone, which holds T at "
                               "cell centres and blurs the lit surface: toward a 5° sun a dense cumulus came out "
                               "grey with weak rims (reference march vs the path tracer at 192×128: image sum "
                               "+27.6 % → +18.3 %, rel. RMSE 35.7 → 26.0 %, rim/body radiance 0.80 → 0.87, tracer "
                               "1.08; the bench's views within 1 point). Each step costs one density (and, with "
                               "detail, one detail) lookup per sample: the reference march (no detail) 1.9× its "
                               "pass time at sun_steps 0 (bench views, 192×128, llvmpipe); with the detail on, "
                               "the lookups the detail's sun correction took before (sunset 1024×768, defaults: "
                               "the march pass 0.93× the one before, in one run). Cost of the march at 640×360 on "
                               "llvmpipe (sunset demo, frame minus the frame without the march, one noisy run on "
                               "shared cores; measured before sun_steps acted without the detail): resolution 1 "
                               "octaves 0 244 ms, octaves 3 sun_steps 0 230 ms, octaves 3 sun_steps 4 951 ms (the "
                               "sun steps are the detail's cost); the defaults (resolution 2, reprojection, "
                               "octaves 3, sun_steps 4) 218 ms")
    wind: tuple = vec_field((10.0, 0.0, 0.0), 3, doc="(x, y, z) m/s the detail noise scrolls with when the clouds "
                            "have no weather (with one, the weather's wind)")
    far_field: bool = bool_field(True, "with a CloudFarFieldPlugin in the scene (else no effect): march on beyond "
                                 "the simulated volume through the layer's altitude band out to ``far_distance`` "
                                 "through a volumetric far field (its cover, the same as the 2D far field's and "
                                 "the ground shadows', times a vertical profile, eroded by the detail noise: "
                                 "``shaders/clouds/raymarch/far.glsl``), cross-faded with the volume over its edge "
                                 "fade; the 2D far-field pass is then culled. Cost of the march pass with the far "
                                 "field over without (which draws the 2D far-field pass instead), 640×360 "
                                 "llvmpipe, defaults, one noisy run on shared cores: flight from 2.5 km 1.5× (380 "
                                 "vs 258 ms), from 320 m under the deck 2.0× (612 vs 298 ms: grazing rays cross "
                                 "tens of km of layer), sunset from the ground 1.3× (273 vs 208 ms)")
    far_distance: float = num_field(60000.0, 1e3, 1e6, "m: how far ``far_field`` marches")
    far_step_growth: float = num_field(0.02, 0.0, 1.0, "the step's growth with distance in the far field (0.02 "
                                       "with 40 m cells: 70 m steps at 2.5 km, 420 m at 20 km; halving it about "
                                       "doubles the far samples)")
    volume: bool = bool_field(True, "march the simulated volume; False: only the far field beyond it (``far_field`` "
                              "with a CloudFarFieldPlugin, else the pass is culled), drawn behind the renderer of "
                              "the volume, e.g. the sprites, which then get the march's volumetric far field "
                              "instead of the 2D pass's")
    enabled: bool = bool_field(True, "False declares nothing (the pass is culled, allocates nothing)")

    def __post_init__(self):
        given = self.resolution                  # as given, for the message
        super().__post_init__()
        if self.resolution not in RESOLUTIONS:
            raise ValueError(f"RaymarchCloudSettings.resolution must be 1, 2 or 4 (march one pixel of every r x r "
                             f"block), got {given!r}")
