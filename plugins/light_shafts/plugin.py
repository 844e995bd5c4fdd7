"""LightShaftsPlugin: shafts of sun light between the clouds, marched through the cloud shadow map
(the default) or blurred from the open sky near the sun in screen space (thesis 7.3.2)."""
from __future__ import annotations

import math

from atmos.graph import PassBuilder, PassContext, RenderPass, TextureDesc
from atmos.plugin import Plugin
from atmos.plugins.clouds import CLOUD_SETS, FAR_FIELD
from atmos.plugins.clouds.shadows.shadow_map import shadow_map_pass
from atmos.plugins.fog import FogMedium
from atmos.composition import Composition
from atmos.plugins.light_shafts.froxels import FroxelShafts, composites_media, uses_froxels
from atmos.plugins.light_shafts.march import MarchedShafts
from atmos.plugins.light_shafts.settings import LightShaftSettings, blur_scale
from atmos.plugins.light_shafts.screen_sun import screen_sun
from atmos.plugins.sky import SkyLight
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures

MASK = "light_shafts_mask"
BLUR = "light_shafts_blur"


def blur_uniforms(program, sun_uv, settings: LightShaftSettings, strength: float) -> None:
    """Set the radial blur's uniforms (shaders/light_shafts/blur.frag)."""
    program["sun_uv"].value = tuple(sun_uv)
    program["samples"].value = settings.samples
    program["density"].value = settings.density
    program["decay"].value = settings.decay
    program["scale"].value = blur_scale(settings, strength)


class LightShaftsPass(RenderPass):
    """``mode="march"``: :class:`~atmos.plugins.light_shafts.march.MarchedShafts` (reads "depth" and,
    when the graph imports them, "cloud_sets"; blends onto "color", alpha kept).

    ``mode="screen"``: mask (reads "color" with its alpha, the sky occlusion, and "depth") → radial
    blur → added onto "color" (blend ONE, ONE; alpha kept).

    The mask and the blur are transients at 1/``downsample`` of the frame; "color" is only sampled
    while the mask is drawn and only written by the last draw, so it is never read and written at once.
    """
    name = "light_shafts"
    phase = "post"
    fuse_media = True   # False: the fog and the air keep their passes where the froxels' apply could composite them (tests)

    def __init__(self, plugin: "LightShaftsPlugin"):
        self.plugin = plugin
        self.mask = self.blur = self.composite = self.marched = self.froxels = None

    def clouds(self) -> bool:
        """Whether the march reads cloud shadows (a clouds plugin imported "cloud_sets")."""
        return self.plugin.graph.imports(CLOUD_SETS)

    def setup_key(self) -> tuple:
        plugin, fog, aerial = self.plugin, self.plugin.fog, self.plugin.aerial()
        graph = plugin.graph
        return (plugin.settings, plugin.gpu.size, graph.imports(CLOUD_SETS), graph.imports(FAR_FIELD),
                fog is not None and (fog.settings, fog.reads_cloud_distance),
                aerial is not None and aerial.reads_cloud_distance, plugin.composites_media())

    def setup(self, builder: PassBuilder) -> None:
        w, h = self.plugin.gpu.size
        d = self.plugin.settings.downsample
        settings, fog = self.plugin.settings, self.plugin.fog
        if settings.mode == "march" and uses_froxels(settings, fog):
            FroxelShafts.declare(builder, settings.froxels, self.clouds(), self.plugin.graph.imports(FAR_FIELD),
                                 fog, self.plugin.aerial(), self.plugin.composites_media())
            return
        if settings.mode == "march":
            MarchedShafts.declare(builder, (w, h), d, self.clouds(), self.plugin.graph.imports(FAR_FIELD),
                                  fog, self.plugin.aerial())
            return
        desc = TextureDesc((math.ceil(w / d), math.ceil(h / d)), components=4, dtype="f2")
        builder.create(MASK, desc)
        builder.create(BLUR, desc)
        builder.read(COLOR)
        builder.read(DEPTH)
        builder.write(COLOR)

    def prepare(self, gpu) -> None:
        fullscreen = "lib/fullscreen.vert"
        self.mask = gpu.program(vertex_shader=fullscreen, fragment_shader="light_shafts/mask.frag")
        self.blur = gpu.program(vertex_shader=fullscreen, fragment_shader="light_shafts/blur.frag")
        self.composite = gpu.program(vertex_shader=fullscreen, fragment_shader="light_shafts/composite.frag")
        self.marched = MarchedShafts(gpu)
        self.froxels = FroxelShafts(self.marched, gpu)

    def release(self) -> None:
        if self.marched is not None:
            self.marched.release()
        if self.froxels is not None:
            self.froxels.history.release()

    def execute(self, frame: PassContext) -> None:
        view, gpu, params = frame.view, frame.gpu, self.plugin.settings
        froxels = params.mode == "march" and uses_froxels(params, self.plugin.fog)
        if not froxels:
            self.froxels.history.release()              # no volume to accumulate: no history kept
        if froxels:
            self.froxels.execute(frame, params, frame.declares(CLOUD_SETS), self.plugin.fog, self.plugin.aerial(),
                                 self.plugin.composites_media())
            return
        if params.mode == "march":
            self.marched.execute(frame, params, frame.declares(CLOUD_SETS), self.plugin.fog, self.plugin.aerial())
            return
        w, h = view.size
        where = screen_sun(view.camera, view.aspect, view.sun.direction, params)
        if where.strength <= 0.0 or params.exposure == 0.0 or params.weight == 0.0:
            return                                      # sun behind, below or far off-screen
        ctx = gpu.ctx
        mask = frame.resource(MASK)
        frame.framebuffer(color=[MASK]).use()
        bind_textures(self.mask, scene_color=frame.resource(COLOR), scene_depth=frame.resource(DEPTH))
        self.mask["mask_size"].value = mask.size
        self.mask["sun_uv"].value = where.uv
        self.mask["threshold"].value = params.threshold
        self.mask["ceiling"].value = params.ceiling
        self.mask["radius"].value = params.radius
        self.mask["aspect"].value = w / h
        frame.fullscreen(self.mask)

        frame.framebuffer(color=[BLUR]).use()
        bind_textures(self.blur, mask=mask)
        blur_uniforms(self.blur, where.uv, params, where.strength)
        frame.fullscreen(self.blur)

        frame.framebuffer(color=[COLOR]).use()
        bind_textures(self.composite, shafts=frame.resource(BLUR))
        ctx.enable(ctx.BLEND)
        ctx.blend_func = ctx.ONE, ctx.ONE
        frame.fullscreen(self.composite)


class LightShaftsPlugin(Plugin):
    """Light shafts (phase post: after the sky, the scene, the clouds and the fog), marched through the
    cloud shadow map or in screen space (``mode``). ``LightShaftsPlugin(settings=None, **fields)``
    with :class:`LightShaftSettings`; ``configure(**changes)`` changes any of them live (next frame;
    ``mode`` and ``downsample`` change the pass's targets). With a FogPlugin the march only takes away the
    fog's in-scatter in cloud shadow (the fog owns the air's light: :class:`LightShaftSettings`), with the
    sky's aerial perspective the air's, with both both (each dimmed by the other in front)."""

    settings_class = LightShaftSettings

    def __init__(self, settings: LightShaftSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.gpu = self.graph = None
        self.fog = None                 # the App's FogMedium (finish), whose in-scatter the march shadows
        self.sky = None                 # the App's SkyLight (finish): its aerial perspective, when on
        self.composition = None         # the App's Composition (finish): which local media there are

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("LightShaftsPlugin needs an App with a GPU context (App(gpu))")
        self.gpu, self.graph = app.gpu, app.graph
        shadow_map_pass(app.graph)
        app.graph.add_pass(LightShaftsPass(self))

    def finish(self, app) -> None:
        self.fog = app.get_resource(FogMedium)
        self.sky = app.get_resource(SkyLight)
        self.composition = app.get_resource(Composition)
        for medium in (self.fog, self.sky):
            if medium is not None:
                medium.composite_elsewhere(self.composites_media)

    def cleanup(self, app) -> None:
        for medium in (self.fog, self.sky):
            if medium is not None:
                medium.composite_elsewhere(None)

    def composites_media(self) -> bool:
        """Whether the froxels' apply composites the fog and the air this frame (their own passes culled):
        :func:`.froxels.composites_media`."""
        return LightShaftsPass.fuse_media and composites_media(self.settings, self.fog, self.aerial(),
                                                               self.composition)

    def aerial(self):
        """The SkyLight when its aerial perspective is on (the march then takes away the air's
        in-scatter in cloud shadow, with a fog as well both, each dimmed by the other); else None."""
        return self.sky if self.sky is not None and self.sky.aerial else None
