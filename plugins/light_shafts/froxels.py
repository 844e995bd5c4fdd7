"""The light shafts from a froxel volume (``LightShaftSettings.froxels``): each of W × H view-ray columns
marched once in D slices through the cloud shadow map (shaders/light_shafts/froxels.comp), then every
pixel reads its sums at its own distance (froxel_apply.comp) — W·H·D samples instead of texels × steps.
Each slice's sample moves every frame and the frames are averaged (:class:`atmos.froxels.FroxelHistory`,
``LightShaftSettings.froxel_history``).
A heterogeneous fog, whose factor along a ray depends on the ray's end, keeps the per-texel march.
With no local medium but the fog, the apply composites the fog and the air's aerial perspective as well
(:func:`composites_media`): one write per pixel for all, their own passes culled. float64 twin: :func:`.reference.froxel_shafts`."""
from __future__ import annotations

from atmos.froxels import FroxelHistory, froxel_knee, volume_desc, volume_image
from atmos.graph import PassBuilder, PassContext, work_groups
from atmos.plugins.clouds import FAR_FIELD
from atmos.plugins.light_shafts.march import MarchedShafts, bind_cloud_distance, march_irradiance
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import write_uniforms

FOG_ONLY = frozenset({"fog"})               # the local media the apply can composite (atmos.composition)
SHAFT_VOLUME = "light_shafts_volume"      # (W, H, D + 1) sums from the camera to each slice boundary


def uses_froxels(settings, fog=None) -> bool:
    """Whether the shafts come from the froxel volume: ``froxels`` set and no heterogeneous fog."""
    return settings.froxels is not None and not (fog is not None and fog.settings.heterogeneous)


def composites_media(settings, fog, aerial, composition) -> bool:
    """Whether the froxels' apply composites the media itself, the fog (the FogMedium) and the air (the
    SkyLight, its aerial perspective on) that there are, exactly as their own passes do, then what the
    shafts take away, in one write: marched shafts from the froxel volume, and no local medium but the
    fog (``composition``'s media writers; none, e.g. a volumetric fog, to keep in order with them)."""
    return ((fog is not None or aerial is not None) and settings.mode == "march" and uses_froxels(settings, fog)
            and composition is not None and composition.media_writers <= FOG_ONLY)


class FroxelShafts:
    """The froxel volume's declarations and dispatches for a LightShaftsPass; the uniforms are the
    march's (``medium``: its :class:`MarchedShafts`)."""

    def __init__(self, medium: MarchedShafts, gpu):
        self.medium = medium
        self.history = FroxelHistory(gpu)

    @staticmethod
    def declare(builder: PassBuilder, froxels, clouds: bool, far_field: bool = False, fog=None, aerial=None,
                composite: bool = False) -> None:
        """``composite``: the apply composites the media (:func:`composites_media`), the air's read too."""
        builder.create(SHAFT_VOLUME, volume_desc(froxels), access="storage")
        if composite and aerial is not None:
            aerial.declare_pixel(builder)
        builder.read(DEPTH)
        builder.read(COLOR, access="storage")
        builder.write(COLOR, access="storage")
        MarchedShafts.declare_medium(builder, clouds, far_field, fog, aerial)

    def execute(self, frame: PassContext, settings, clouds: bool, fog=None, aerial=None,
                composite: bool = False) -> None:
        """Fill the volume, resolve its history and apply it; with ``composite`` (:func:`composites_media`)
        the apply composites the fog and the air too, and them alone while the sun is down (no shafts)."""
        irradiance = march_irradiance(frame.view.sun, settings)
        far_field = clouds and frame.declares(FAR_FIELD)
        apply = self.medium.program(far_field, fog, aerial, "light_shafts/froxel_apply.comp", composite)
        if irradiance is None:
            if composite:
                self.apply(frame, apply, settings, fog, aerial, frame.resource(SHAFT_VOLUME), lit=False,
                           composite=True)
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
        self.apply(frame, apply, settings, fog, aerial, volume, lit=True, composite=composite)

    def apply(self, frame: PassContext, apply, settings, fog, aerial, volume, lit: bool, composite: bool) -> None:
        """Dispatch the apply over every pixel: it reads the sums (no shadows, sun or phase), the fog's
        colour and the clouds' distance where it takes light away; with ``composite`` the air's aerial
        perspective too (its froxel volume filled here), ``lit`` its shafts_lit (False: the media alone,
        the volume unread)."""
        write_uniforms(apply, froxel_knee=froxel_knee(settings.max_distance), max_distance=settings.max_distance,
                       shafts_lit=int(lit))
        if fog is not None:
            self.medium.fog_uniforms(frame, apply, fog, settings)
        elif aerial is not None:
            bind_cloud_distance(frame, apply)
        units = aerial.use_pixel(frame, apply) if composite and aerial is not None else []
        color = frame.image(COLOR)
        frame.dispatch(apply, work_groups(color.size, (8, 8)), images={"color_image": color},
                       textures={"scene_depth": DEPTH, "shaft_volume": volume})
        if units:
            aerial.clear_pixel(units)
