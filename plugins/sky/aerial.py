"""The physical sky's aerial perspective: the pass "aerial_perspective" (phase media).

With ``SkySettings.model = "physical"`` and ``aerial_perspective`` on, every pixel that shows the scene
(terrain, ground, meshes) gets the sunlight the air between it and the camera scatters toward the
camera, and loses what that air absorbs and scatters away: ``C → L + T·C``, both marched through the
sky's own atmosphere and LUTs (``shaders/sky/aerial.comp``; float64:
:func:`atmos.plugins.sky.atmosphere.aerial_perspective`). Distant hills turn the sky's blue by day and
its orange at sunset, with no fog colour to choose. Clouds that give the media passes their own distance
(:mod:`atmos.composition`) are hazed by it. It runs after the other media passes (local fog lies in
front of the surfaces it covers; the atmosphere spans the whole ray); with a fog it mixes the air with
the fog along the ray (:mod:`atmos.composition` media_mix): an opaque fog hides the air behind it, and
neither medium's light is counted twice. Culled with Preetham or off, and while another pass composites
the air (:class:`atmos.composition.CompositedElsewhere`: the light shafts' froxel apply runs
``shaders/sky/aerial_pixel.glsl`` itself, through :meth:`declare_pixel` and :meth:`use_pixel`).

With ``SkySettings.aerial_froxels`` (default (32, 32, 64)) the pass first fills the transient
"aerial_volume", a froxel volume: each froxel column's ray marched slice by slice (slices squared out
to :func:`volume_range`; ``shaders/sky/aerial_volume.comp``), and every pixel reads it trilinearly
instead of marching; None marches every pixel in ``aerial_steps`` (``benchmarks/bench_sky.py`` measures
both against a 96-step float64 march).
"""
from __future__ import annotations

import math

import numpy as np

from atmos.camera import view_basis
from atmos.composition import CLOUD_DISTANCE, MEDIA_LIGHT, MEDIA_TRANSMITTANCE
from atmos.gpu import clamp_sampler
from atmos.graph import ComputePass, PassContext, TextureDesc
from atmos.plugins.sky.luts import SKY_LUTS, atmosphere_defines, set_atmosphere_uniforms, view_radius
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_images, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch

AERIAL = "aerial_perspective"
AERIAL_VOLUME = "aerial_volume"          # the froxel volume (a transient of this pass)
GROUP = 8                                # aerial_volume.comp's work group: 8 x 8 froxel columns


def volume_range(camera, aspect: float, settings) -> float:
    """m: the froxel volume's reach, the farthest a pixel's surface can be (the far plane along the
    frame's corner ray), at most the longest ray through the atmosphere that can end on the ground
    (to the horizon and on to the top of the atmosphere); longer rays (far clouds) march themselves."""
    corner = float(np.linalg.norm(view_basis(camera, aspect) @ np.array([1.0, 1.0, 1.0])))
    rg, rt = settings.planet_radius, settings.top_radius
    r = min(max(rg + float(camera.position[1]), rg), rt)
    atmosphere = math.sqrt(max(r * r - rg * rg, 0.0)) + math.sqrt(rt * rt - rg * rg)
    return min(float(camera.far) * corner, atmosphere)


def active(settings) -> bool:
    """Whether the sky's settings ask for the aerial perspective (it needs the physical model)."""
    return settings.model == "physical" and settings.aerial_perspective


class AerialPerspectivePass(ComputePass):
    """See the module docstring; ``plugin`` is the SkyPlugin (its settings, composition and graph)."""
    name = AERIAL
    phase = "media"
    compute = "sky/aerial.comp"
    sampler = None          # the clamping sampler of the froxel volume, made on first use (use_pixel)

    @property
    def after(self) -> tuple[str, ...]:
        """Every other media pass of the graph (the fog, volumetric fog, a game's haze)."""
        return tuple(p.name for p in self.plugin.graph.passes if p.phase == self.phase and p is not self)

    def clouds(self) -> bool:
        return self.plugin.composition.distance

    def media(self) -> bool:
        return self.plugin.composition.media

    def defines(self) -> dict:
        return {**self.pixel_defines(), "AERIAL_CLOUDS": int(self.clouds()), "AERIAL_MEDIA": int(self.media())}

    def pixel_defines(self) -> dict:
        """sky/aerial_pixel.glsl's variant: the atmosphere's, its step count and whether it reads the froxels."""
        return {**atmosphere_defines(), "AERIAL_STEPS": self.plugin.settings.aerial_steps,
                "AERIAL_VOLUME": int(self.froxels() is not None)}

    def froxels(self):
        return self.plugin.settings.aerial_froxels

    def setup(self, builder) -> None:
        if not active(self.plugin.settings) or self.plugin.light.composited_elsewhere:
            return                              # declares nothing: culled, nothing allocated
        self.declare_pixel(builder)
        builder.read(DEPTH)
        builder.read(COLOR, access="storage")   # composites onto it in place
        builder.write(COLOR, access="storage")
        if self.clouds():
            builder.read(CLOUD_DISTANCE)
        if self.media():                        # a fog in front: the air mixed with it (atmos.composition)
            builder.read(MEDIA_LIGHT)
            builder.read(MEDIA_TRANSMITTANCE)

    def declare_pixel(self, builder) -> None:
        """What sky/aerial_pixel.glsl reads, declared by the pass that runs it: the LUTs, and the froxel
        volume it fills (created by that pass)."""
        if self.froxels() is not None:
            builder.create(AERIAL_VOLUME, TextureDesc(tuple(self.froxels()), components=4, dtype="f4", storage=True),
                           access="storage")
        builder.read(SKY_LUTS)

    def release(self) -> None:
        if self.sampler is not None:
            self.sampler.release()
            self.sampler = None
        super().release()

    def execute(self, frame: PassContext) -> None:
        p = self.program
        units = self.use_pixel(frame, p)
        # graph resources under the names the shader's samplers carry (atmos.composition)
        textures = {name: name for name in (DEPTH, CLOUD_DISTANCE, MEDIA_LIGHT, MEDIA_TRANSMITTANCE)
                    if frame.declares(name)}
        textures["scene_depth"] = textures.pop(DEPTH)
        frame.dispatch(p, self.groups(frame.image(COLOR).size), textures=textures, images={"color_image": COLOR})
        self.clear_sampler(units)

    def use_pixel(self, frame: PassContext, program) -> list[int]:
        """Everything sky/aerial_pixel.glsl reads, for ``program`` in a pass that declared it
        (:meth:`declare_pixel`): the froxel volume filled and bound (clamped), the LUTs, the atmosphere's
        uniforms, ``view_r`` and ``aerial_range``. Returns the units to :meth:`clear_sampler` after the dispatch."""
        if self.sampler is None:                # whichever pass runs it first (this one or the shafts')
            self.sampler = clamp_sampler(frame.gpu.ctx)
        view, settings = frame.view, self.plugin.settings
        frame.resource(SKY_LUTS).bind(program)
        values = dict(view_r=view_radius(settings.atmosphere, view.camera),
                      aerial_range=volume_range(view.camera, view.aspect, settings.atmosphere))
        volume = frame.resource(AERIAL_VOLUME) if frame.declares(AERIAL_VOLUME) else None
        if volume is not None:
            self._fill(frame.gpu, volume, values)
        units = bind_textures(program, sampler=self.sampler, aerial_volume=volume) if volume is not None else []
        set_atmosphere_uniforms(program, settings.atmosphere)
        write_uniforms(program, values)
        return units

    def clear_sampler(self, units) -> None:
        """Unbind the clamping sampler from ``units`` (:meth:`use_pixel`'s)."""
        for unit in units:
            self.sampler.clear(unit)

    def _fill(self, gpu, volume, values) -> None:
        """The froxel volume: one invocation per froxel column, marching through the slices (aerial_volume.comp)."""
        c = gpu.program(compute_shader="sky/aerial_volume.comp", defines=atmosphere_defines())
        set_atmosphere_uniforms(c, self.plugin.settings.atmosphere)
        write_uniforms(c, values)
        bind_images(c, aerial_volume=volume)
        w, h, _ = volume.size
        dispatch(c, -(-w // GROUP), -(-h // GROUP), 1)
