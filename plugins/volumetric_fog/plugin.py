"""VolumetricFogPlugin and its pass: the FBM medium ray-marched over the scene, occluded by depth."""
from __future__ import annotations

import numpy as np

from atmos.composition import MEDIA_LIGHT, MEDIA_TRANSMITTANCE, composition
from atmos.froxels import FroxelHistory, froxel_knee, volume_desc, volume_image
from atmos.gpu.uniforms import write_uniforms
from atmos.graph import ComputePass, PassContext, work_groups
from atmos.lighting import Sun, sun_and_day
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.plugins.clouds import CLOUD_SETS
from atmos.plugins.clouds.shadows.shadow_map import SHADOW_MAP, cloud_extinctions, read_shadow_map, shadow_map_pass, use_shadow_map
from atmos.plugins.sky import SkyLight
from atmos.plugins.volumetric_fog.noise import Lattice, noise_defines, noise_kind
from atmos.plugins.volumetric_fog.settings import VolumetricFogSettings

HORIZON_SAMPLES = 16      # azimuths of the sky's horizon radiance averaged into the ambient
FOG_VOLUME = "volumetric_fog_volume"     # the froxel volume (a transient of the pass; settings.froxels)


def sun_terms(sun: Sun, settings: VolumetricFogSettings, sky_ambient=None):
    """(unit direction toward the sun, sun_light, ambient_light): the sun fades out below the horizon;
    the ambient follows the day, or is ``settings.ambient`` ⊙ ``sky_ambient`` (the sky's mean horizon
    radiance, ``ambient_from="sky"``)."""
    s, day = sun_and_day(sun)
    sun_light = np.asarray(sun.color, np.float64) * settings.scattering * day
    if sky_ambient is not None:
        ambient_light = np.asarray(settings.ambient) * np.asarray(sky_ambient, np.float64)
    else:
        ambient_light = np.asarray(settings.ambient) * (0.1 + 0.9 * day)
    return s, sun_light, ambient_light


def set_medium_uniforms(program, settings: VolumetricFogSettings, sun: Sun, time: float, sky_ambient=None) -> None:
    """Write every uniform of ``volumetric_fog/medium.glsl`` (the sun's direction it reads from the frame
    block, ``lib/frame.glsl``: the frame's Sun, whose direction is ``sun``'s)."""
    _, sun_light, ambient_light = sun_terms(sun, settings, sky_ambient)
    values = {"center": settings.center, "scale": settings.scale, "bias": settings.bias, "falloff": settings.falloff,
              "frequency": settings.frequency, "wind": settings.wind, "fog_time": float(time),
              "octaves": settings.octaves, "seed": settings.seed, "absorption": settings.absorption,
              "steps": settings.steps, "light_steps": settings.light_steps, "light_step": settings.light_step,
              "max_distance": settings.max_distance, "sun_light": tuple(sun_light),
              "ambient_light": tuple(ambient_light)}
    write_uniforms(program, values)


class VolumetricFogPass(ComputePass):
    """A compute pass, one invocation per pixel: reads ``depth``, composites (in-scattered light,
    transmittance) onto ``color`` in place, rgb = light + T · rgb, alpha (the sky occlusion of
    :mod:`atmos.render_core`) kept: the medium tints the sky, it does not hide it. Where the aerial
    perspective mixes the air with the local media, onto the media targets too. With clouds in the
    scene (``cloud_shadows``) the sunlight each sample receives passes through their shadow map."""
    name = "volumetric_fog"
    phase = "media"
    compute = "volumetric_fog/fog.comp"
    reads = (COLOR, DEPTH)
    writes = (COLOR,)

    def setup(self, builder) -> None:
        super().setup(builder)
        froxels = self.plugin.settings.froxels
        if froxels is not None:                    # layer 0 is the camera: D slices, D + 1 layers
            builder.create(FOG_VOLUME, volume_desc(froxels), access="storage")
        if self.cloud_shadows():
            read_shadow_map(builder, self.plugin.graph)
        if self.plugin.composition.media:          # the aerial perspective mixes the air with it
            for name in (MEDIA_LIGHT, MEDIA_TRANSMITTANCE):
                builder.read(name, access="storage")
                builder.write(name, access="storage")

    def cloud_shadows(self) -> bool:
        """Whether the sunlight passes through the clouds' shadow map: ``cloud_shadows`` and a clouds plugin
        imported "cloud_sets"."""
        return self.plugin.settings.cloud_shadows and self.plugin.graph.imports(CLOUD_SETS)

    def medium_defines(self) -> dict:
        """volumetric_fog/medium.glsl's defines: the noise's, and FOG_CLOUD_SHADOWS (:meth:`cloud_shadows`)."""
        defines = noise_defines(self.plugin.settings, self.gpu)
        return {**defines, "FOG_CLOUD_SHADOWS": 1} if self.cloud_shadows() else defines

    def defines(self) -> dict:
        return {"LOCAL_MEDIA": int(self.plugin.composition.media), **self.medium_defines()}

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.history = FroxelHistory(gpu)      # the froxel volume's temporal accumulation (settings.froxels)
        self.lattice = Lattice(gpu)            # the filtered noise's lattice, baked once per seed

    def release(self) -> None:
        self.history.release()
        self.lattice.release()

    def execute(self, frame: PassContext) -> None:
        view, settings = frame.view, self.plugin.settings
        images = {"color_image": COLOR}
        if frame.declares(MEDIA_LIGHT):
            images.update(media_light_image=MEDIA_LIGHT, media_transmittance_image=MEDIA_TRANSMITTANCE)
        color = frame.image(COLOR)
        noise = {}
        if noise_kind(settings, self.gpu) == "filtered":
            noise["fog_lattice"] = self.lattice.sync(settings.seed)
        else:
            self.lattice.release()
        if settings.froxels is None:
            self.history.release()                     # no volume to accumulate: no history kept
            p = self.program
            set_medium_uniforms(p, settings, view.sun, self.plugin.time(view), self.plugin.sky_ambient(view))
            if frame.declares(SHADOW_MAP):
                use_shadow_map(frame, p, *cloud_extinctions(frame))
            frame.dispatch(p, self.groups(color.size), textures={"scene_depth": DEPTH, **noise},
                           images=images)
            return
        fill = self.gpu.program(compute_shader="volumetric_fog/froxels.comp", defines=self.medium_defines())
        apply = self.gpu.program(compute_shader="volumetric_fog/froxel_apply.comp",
                                 defines={"LOCAL_MEDIA": int(self.plugin.composition.media)})
        volume = volume_image(frame, FOG_VOLUME)
        for p in (fill, apply):
            write_uniforms(p, froxel_knee=froxel_knee(settings.max_distance), max_distance=settings.max_distance)
        set_medium_uniforms(fill, settings, view.sun, self.plugin.time(view), self.plugin.sky_ambient(view))
        if frame.declares(SHADOW_MAP):
            use_shadow_map(frame, fill, *cloud_extinctions(frame))
        write_uniforms(fill, froxel_jittered=int(self.history.jittered(view.clock.frame, settings.froxel_history)))
        frame.dispatch(fill, work_groups(volume.size[:2], (8, 8)), images={"fog_volume": volume}, textures=noise)
        volume = self.history.resolve(frame, volume, settings.max_distance, froxel_knee(settings.max_distance),
                                      settings.froxel_history)
        frame.dispatch(apply, self.groups(color.size), images=images,
                       textures={"scene_depth": DEPTH, "fog_volume": volume})


class VolumetricFogPlugin(Plugin):
    """Ray-marched FBM fog: ``VolumetricFogPlugin(settings=None, **fields)`` with
    :class:`VolumetricFogSettings`; ``configure(**changes)`` changes any of them live (next frame).
    The noise drifts with the App's clock (``clock.frame_time``) unless ``animate=False``.
    """

    settings_class = VolumetricFogSettings
    _sky: SkyLight | None = None

    def time(self, view) -> float:
        """Seconds the noise has drifted for: the view's frame time (0 unless ``animate``)."""
        return float(view.time) if self.settings.animate else 0.0

    def sky_ambient(self, view):
        """The sky's mean horizon radiance at the camera's altitude (``ambient_from="sky"``), else None."""
        if self.settings.ambient_from != "sky":
            return None
        if self._sky is None:
            raise ValueError("VolumetricFogSettings.ambient_from='sky' takes the light of the App's sky, and the "
                             "App has no SkyPlugin; add one or use ambient_from='fixed'")
        return self._sky.horizon(view.sun, max(float(view.camera.position[1]), 0.0), HORIZON_SAMPLES).mean(0)

    def build(self, app) -> None:
        self.graph = app.graph
        shadow_map_pass(app.graph)                 # baked when clouds are there (culled otherwise)
        self.composition = composition(app)
        self.composition.media_writers.add(VolumetricFogPass.name)   # a local medium (atmos.composition)
        app.graph.add_pass(VolumetricFogPass(self))

    def finish(self, app) -> None:
        self._sky = app.get_resource(SkyLight)      # the sky's published light, if the App has a sky

    def cleanup(self, app) -> None:
        self.composition.media_writers.discard(VolumetricFogPass.name)
