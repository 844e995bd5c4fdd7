"""The light shafts from a froxel volume (``LightShaftSettings.froxels``): each of W × H view-ray columns
marched once in D slices through the cloud shadow map (shaders/light_shafts/froxels.comp), then every
pixel reads its sums at its own distance (froxel_apply.comp) — W·H·D samples instead of texels × steps.
Each slice's sample moves every frame and the frames are averaged (:class:`atmos.froxels.FroxelHistory`,
``LightShaftSettings.froxel_history``).
A heterogeneous fog, whose factor along a ray depends on the ray's end, keeps the per-texel march.
With the fog as the only local medium the apply composites the fog as well (:func:`composites_fog`):
one write per pixel for both, the fog's own pass culled. float64 twin: :func:`.reference.froxel_shafts`."""
from __future__ import annotations

from atmos.froxels import FroxelHistory, froxel_knee, volume_desc, volume_image
from atmos.graph import PassBuilder, PassContext, work_groups
from atmos.plugins.clouds import FAR_FIELD
from atmos.plugins.light_shafts.march import MarchedShafts, bind_cloud_distance, march_irradiance
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import write_uniforms

SHAFT_VOLUME = "light_shafts_volume"      # (W, H, D + 1) sums from the camera to each slice boundary


def uses_froxels(settings, fog=None) -> bool:
    """Whether the shafts come from the froxel volume: ``froxels`` set and no heterogeneous fog."""
    return settings.froxels is not None and not (fog is not None and fog.settings.heterogeneous)


def composites_fog(settings, fog, aerial, composition) -> bool:
    """Whether the froxels' apply composites the fog itself (exactly as the fog's pass does, then what the
    shafts take away, in one write): marched shafts from the froxel volume, a fog (the FogMedium) that is
    the only local medium (``composition``'s media writers; no volumetric fog to keep in order with it)
    and no aerial perspective (which mixes the air with the local media in its own pass)."""
    return (fog is not None and aerial is None and settings.mode == "march" and uses_froxels(settings, fog)
            and composition is not None and composition.media_writers == {"fog"})


class FroxelShafts:
    """The froxel volume's declarations and dispatches for a LightShaftsPass; the uniforms are the
    march's (``medium``: its :class:`MarchedShafts`)."""

    def __init__(self, medium: MarchedShafts, gpu):
        self.medium = medium
        self.history = FroxelHistory(gpu)

    @staticmethod
    def declare(builder: PassBuilder, froxels, clouds: bool, far_field: bool = False, fog=None, aerial=None) -> None:
        builder.create(SHAFT_VOLUME, volume_desc(froxels), access="storage")
        builder.read(DEPTH)
        builder.read(COLOR, access="storage")
        builder.write(COLOR, access="storage")
        MarchedShafts.declare_medium(builder, clouds, far_field, fog, aerial)

    def execute(self, frame: PassContext, settings, clouds: bool, fog=None, aerial=None,
                composite_fog: bool = False) -> None:
        """Fill the volume, resolve its history and apply it; with ``composite_fog`` (:func:`composites_fog`)
        the apply composites the fog too, and alone while the sun is down (no shafts to shadow)."""
        irradiance = march_irradiance(frame.view.sun, settings)
        far_field = clouds and frame.declares(FAR_FIELD)
        apply = self.medium.program(far_field, fog, aerial, "light_shafts/froxel_apply.comp", composite_fog)
        if irradiance is None:
            if composite_fog:
                self.apply(frame, apply, settings, fog, aerial, frame.resource(SHAFT_VOLUME), lit=False)
            return
        fill = self.medium.program(far_field, fog, aerial, "light_shafts/froxels.comp")
        knee = froxel_knee(settings.max_distance)
        self.medium.set_medium(frame, fill, settings, clouds, irradiance, fog, aerial)
        write_uniforms(fill, froxel_knee=knee, froxel_jittered=int(self.history.jittered(frame.view.clock.frame,
                                                                                         settings.froxel_history)))
        volume = volume_image(frame, SHAFT_VOLUME)
        frame.dispatch(fill, work_groups(volume.size[:2], (8, 8)), images={"shaft_volume": volume})
        volume = self.history.resolve(frame, volume, settings.max_distance, knee, settings.froxel_history,
                                      key=(far_field, fog is not None, aerial is not None, clouds))
        self.apply(frame, apply, settings, fog, aerial, volume, lit=True)

    def apply(self, frame: PassContext, apply, settings, fog, aerial, volume, lit: bool) -> None:
        """Dispatch the apply over every pixel: it reads the sums (no shadows, sun or phase), the fog's
        colour and the clouds' distance where it takes light away; ``lit`` is its shafts_lit where it
        composites the fog (False: the fog alone, the volume unread)."""
        write_uniforms(apply, froxel_knee=froxel_knee(settings.max_distance), max_distance=settings.max_distance,
                       shafts_lit=int(lit))
        if fog is not None:
            self.medium.fog_uniforms(frame, apply, fog, settings)
        elif aerial is not None:
            bind_cloud_distance(frame, apply)
        color = frame.image(COLOR)
        frame.dispatch(apply, work_groups(color.size, (8, 8)), images={"color_image": color},
                       textures={"scene_depth": DEPTH, "shaft_volume": volume})
