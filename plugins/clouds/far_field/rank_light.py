"""RankLight: the volume's own light by column rank, which the far fields light their columns with.

The far field gives a point of rank r the volume's column sum at r (:mod:`.cover`); this measure gives
it the light of the volume's columns of that rank too (``shaders/clouds/far_field/light_by_rank.comp``,
float64 reference :func:`atmos.plugins.clouds.far_field.reference.light_by_rank`): the mean sun
transmittances of the octaves (``medium.octave_transmittances``) and, where the sets carry a diffusion field, its mean
(phi, F), each as seen from above and from below; both per height bin for the ray march's
volumetric far field; the height their light comes from (where the 2D far field takes the sun's
colour); and the clouds' thickness (the height their density spans), how high the 2D
far field's clouds stand when seen at a slant (``far.comp`` slant_rank). So the far field is as bright per cover as the volume at every sun, not a guess
from a slanted column. Two small dispatches after the cover, once per simulation step and shown set (:meth:`FarFieldLayer.prepare`).
"""
from __future__ import annotations

from atmos.plugins.clouds.far_field.columns import INTERVALS, rank_texture, read_rank_texture, use_columns
from atmos.plugins.clouds.volume.light import cell_tau
from atmos.plugins.clouds.light.diffusion import DIFFUSION
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures, write_uniforms

READS = {"transmittance": "trans", DIFFUSION: "diffusion"}   # light_by_rank.comp's inputs beside columns.glsl's
FIELD_BINS = 16                  # light_by_rank.comp's most height bins (sun_profile, field_profile)
SUMS = INTERVALS * 2 * 11 + INTERVALS * FIELD_BINS * 9      # its Sums buffer (uint32): the slots, the bins
GROUP = 256                      # its work group (columns per group in STAGE 0)


class RankLight:
    """The textures of one measure (GL objects of one GpuContext): ``sun`` (INTERVALS, 2) rgba32f,
    ``thickness`` (INTERVALS, 1) and ``height`` (INTERVALS, 2) r32f, ``sun_profile`` (INTERVALS, bins) rgba32f, and with a field
    ``field`` (INTERVALS, 2) and ``field_profile`` (INTERVALS, bins) rgba32f."""

    def __init__(self, gpu):
        self.gpu = gpu
        self.sun = self.thickness = self.height = self.sun_profile = self.field = self.field_profile = self.sums = None
        self.has_field = False           # the last measure took a diffusion field
        self._bins = 0                   # the profiles' height bins

    def measure(self, sim, cover_buffer, attenuation: float, heights: int) -> None:
        """Measure mix(A, B, t) of ``sim`` (the frame's CloudSets) ranked by the quantiles in
        ``cover_buffer`` (cover.comp's, already written), the octaves' ``attenuation`` a, at ``heights``
        samples per column: one invocation per column, then one work group for the means."""
        self.has_field = DIFFUSION in sim.a and DIFFUSION in sim.b
        shading = "transmittance" in sim.a and "transmittance" in sim.b
        bins = min(int(heights), FIELD_BINS)
        self.allocate(bins)
        inputs = {f"{sampler}_{x}": s[name] for name, sampler in READS.items() if name in sim.a and name in sim.b
                  for x, s in (("a", sim.a), ("b", sim.b))}
        values = dict(heights=int(heights), bins=bins, has_shading=int(shading), attenuation=float(attenuation),
                      column_tau=cell_tau(sim.settings))
        columns = sim.shape[0] * sim.shape[2]
        for stage, groups in ((0, -(-columns // GROUP)), (1, 1)):
            c = self.gpu.program(compute_shader="clouds/far_field/light_by_rank.comp",
                                 defines={"FIELD": int(self.has_field), "STAGE": stage})
            use_columns(c, sim)
            bind_textures(c, inputs)
            bind_buffers(c, Cover=cover_buffer, Sums=self.sums)
            write_uniforms(c, values)
            if stage == 1:
                bind_images(c, sun_by_rank=self.sun, thickness_by_rank=self.thickness, height_by_rank=self.height,
                            sun_profile=self.sun_profile)
                if self.has_field:
                    bind_images(c, field_column=self.field, field_profile=self.field_profile)
            dispatch(c, groups)

    def allocate(self, bins: int) -> None:
        """The textures for ``bins`` height bins (the field's while :attr:`has_field`), kept while they fit."""
        if self.sun is None:
            self.sun, self.thickness = rank_texture(self.gpu, 2, 4), rank_texture(self.gpu, 1, 1)
            self.height = rank_texture(self.gpu, 2, 1)
            self.sums = self.gpu.track(self.gpu.ctx.buffer(bytes(4 * SUMS)))    # zero; STAGE 1 clears it
        if self.sun_profile is None or self._bins != bins:
            self._release_profiles()
            self.sun_profile, self._bins = rank_texture(self.gpu, bins, 4), bins
        if self.has_field and self.field_profile is None:
            self.field, self.field_profile = rank_texture(self.gpu, 2, 4), rank_texture(self.gpu, bins, 4)

    def use(self, program) -> None:
        """Bind the textures the program declares (far_sun_by_rank, far_thickness_by_rank, far_height_by_rank,
        far_sun_profile, far_field_light, far_field_light_profile)."""
        textures = dict(far_sun_by_rank=self.sun, far_thickness_by_rank=self.thickness, far_height_by_rank=self.height,
                        far_sun_profile=self.sun_profile)
        if self.has_field:
            textures.update(far_field_light=self.field, far_field_light_profile=self.field_profile)
        bind_textures(program, {name: texture for name, texture in textures.items() if texture is not None})

    def read(self) -> dict:
        """The last measure as float64 arrays (a GPU → CPU copy: tests and tools): ``sun`` (INTERVALS, 2, 4)
        [k, v] = the mean octave transmittances of rank interval k seen from above (v = 0) and below (1),
        ``thickness`` (INTERVALS,) its clouds' mean height as a fraction of the layer, ``height`` (INTERVALS, 2)
        the mean height fraction its light comes from seen from above and below, ``sun_profile``
        (INTERVALS, bins, 4) the mean octave transmittances per height bin;
        with a field also ``field`` (INTERVALS, 2, 4) the mean (phi, F) likewise and ``field_profile``
        (INTERVALS, bins, 4) per height bin."""
        if self.sun is None:
            raise RuntimeError("RankLight.read: nothing measured yet (FarFieldLayer.prepare measures it)")
        out = {"sun": read_rank_texture(self.sun), "thickness": read_rank_texture(self.thickness)[:, 0, 0],
               "height": read_rank_texture(self.height)[:, :, 0],
               "sun_profile": read_rank_texture(self.sun_profile)}
        if self.has_field:
            out.update(field=read_rank_texture(self.field), field_profile=read_rank_texture(self.field_profile))
        return out

    def _release_profiles(self) -> None:
        for texture in (self.sun_profile, self.field, self.field_profile):
            if texture is not None:
                texture.release()
        self.sun_profile = self.field = self.field_profile = None

    def release(self) -> None:
        self._release_profiles()
        for resource in (self.sun, self.thickness, self.height, self.sums):
            if resource is not None:
                resource.release()
        self.sun = self.thickness = self.height = self.sums = None
