"""CloudMarchPlugin: the same clouds ray-marched with many samples — the reference image the
sprite renderer's error is measured against (``benchmarks/bench_cloud_render.py``).

It reads its placement, extinction and light from a :class:`CloudRenderPlugin` (pass
``renderer``), so both draw the same volume the same way; switch the two with their ``enabled``
flags. Pass "cloud_march" (phase translucent, after "cloud_render"): reads "depth" and
"cloud_sets", blends onto "color".
"""
from __future__ import annotations

from dataclasses import dataclass

from atmos.camera import set_camera_uniforms
from atmos.checks import CheckedSettings, check_bool, check_int
from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.plugin import Plugin
from atmos.plugins.cloud_render.binding import bind_volume, clamp_sampler, unbind_volume
from atmos.plugins.cloud_render.plugin import CloudRenderPlugin
from atmos.plugins.clouds.sets import CLOUD_SETS, CloudSets
from atmos.render_core import COLOR, DEPTH


@dataclass(frozen=True)
class CloudMarchSettings(CheckedSettings):
    """``steps``: midpoint samples per view ray, 1..65536 (a shader define: the pass fetches that
    program variant on the next frame); ``enabled`` False skips drawing. All live."""
    steps: int = 512
    enabled: bool = True

    def __post_init__(self):
        o = "CloudMarchSettings"
        self.store(dict(steps=check_int(o, "steps", self.steps, 1, 65536),
                        enabled=check_bool(o, "enabled", self.enabled)))


class CloudMarchPlugin(Plugin):
    """``CloudMarchPlugin(renderer, settings=None, **fields)`` with :class:`CloudMarchSettings`;
    ``renderer``: the CloudRenderPlugin whose placement and extinction it uses."""

    settings_class = CloudMarchSettings

    def __init__(self, renderer: CloudRenderPlugin, settings: CloudMarchSettings | None = None, **fields):
        if not isinstance(renderer, CloudRenderPlugin):
            raise ValueError(f"CloudMarchPlugin.renderer must be a CloudRenderPlugin, got {type(renderer).__name__}")
        super().__init__(settings, **fields)
        self.renderer = renderer

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("CloudMarchPlugin needs an App with a GPU context (App(gpu))")
        app.graph.add_pass(CloudMarchPass(self))


class CloudMarchPass(RenderPass):
    name = "cloud_march"
    phase = "translucent"
    after = ("cloud_render",)               # it needs a CloudRenderPlugin: drawn over its sprites when both are on

    def __init__(self, plugin: CloudMarchPlugin):
        self.plugin = plugin
        self.gpu = self.sampler = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(DEPTH)
        builder.read(CLOUD_SETS)
        builder.read(COLOR)                 # blends onto it
        builder.write(COLOR)

    def prepare(self, gpu) -> None:
        self.gpu = gpu
        self.sampler = clamp_sampler(gpu.ctx)

    @property
    def program(self):
        """The variant for the current ``steps`` (the GPU context's program cache: a dict lookup)."""
        return self.gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="cloud_render/march.frag",
                                defines={"MARCH_STEPS": self.plugin.settings.steps})

    def execute(self, frame: PassContext) -> None:
        if not self.plugin.settings.enabled:
            return
        view, p = frame.view, self.program
        sim: CloudSets = frame.resource(CLOUD_SETS)
        renderer = self.plugin.renderer
        layout = renderer.layout(sim)
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_over()
        set_camera_uniforms(p, view.camera, view.aspect)
        for name, value in (("layer_min", layout.lo), ("layer_max", layout.hi), ("cell_size", layout.cell)):
            p[name].value = tuple(float(v) for v in value)
        p["sigma_t"].value = renderer.sigma_t(sim)
        bind_volume(p, sim, self.sampler, view.sun, renderer.settings.octaves)
        frame.resource(DEPTH).use(5)
        try:
            frame.fullscreen(p)
        finally:
            unbind_volume(self.sampler)

    def release(self) -> None:
        if self.sampler is not None:
            self.sampler.release()
            self.sampler = None
