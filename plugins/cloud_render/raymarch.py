"""CloudReferencePlugin: the same clouds ray-marched with many samples — the reference image the
sprite renderer's error is measured against (``benchmarks/bench_cloud_render.py``).

It reads its placement, extinction and light from a :class:`CloudRenderPlugin` (pass
``renderer``), so both draw the same volume the same way; add it after that plugin and switch the
two with their ``enabled`` flags. Pass "clouds_reference": reads "depth", blends into "color".
"""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, set_camera_uniforms
from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.plugins.cloud_render.binding import bind_volume, clamp_sampler, unbind_volume
from atmos.plugins.cloud_render.plugin import CloudRenderPlugin
from atmos.plugins.clouds.simulation import CloudSimulation
from atmos.render_core import COLOR, DEPTH


class CloudReferencePlugin(Plugin):
    """``steps`` midpoint samples per view ray (an int 1..65536); ``enabled`` False skips drawing."""

    def __init__(self, renderer: CloudRenderPlugin, steps: int = 512, enabled: bool = True):
        if not isinstance(renderer, CloudRenderPlugin):
            raise ValueError(f"CloudReferencePlugin.renderer must be a CloudRenderPlugin, got {type(renderer).__name__}")
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 1 <= steps <= 65536:
            raise ValueError(f"CloudReferencePlugin.steps must be an int in 1..65536, got {steps!r}")
        self.renderer, self.steps, self.enabled = renderer, int(steps), bool(enabled)

    def build(self, app) -> None:
        if app.graph is None or app.get_resource(CloudSimulation) is None:
            raise ValueError("CloudReferencePlugin needs an App with a GPU context and CloudsPlugin added before it")
        app.graph.add_pass(CloudMarchPass(self))


class CloudMarchPass(RenderPass):
    name = "clouds_reference"

    def __init__(self, plugin: CloudReferencePlugin):
        self.plugin = plugin
        self.program = self.sampler = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(DEPTH)
        builder.write(COLOR)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="cloud_render/march.frag",
                                   defines={"MARCH_STEPS": self.plugin.steps})
        self.sampler = clamp_sampler(gpu.ctx)

    def execute(self, frame: PassContext) -> None:
        if not self.plugin.enabled:
            return
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        sim = app.resource(CloudSimulation)
        renderer = self.plugin.renderer
        layout = renderer.layout(sim)
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_over()
        set_camera_uniforms(p, app.resource(Camera), gpu.size[0] / gpu.size[1])
        for name, value in (("layer_min", layout.lo), ("layer_max", layout.hi), ("cell_size", layout.cell)):
            p[name].value = tuple(float(v) for v in value)
        p["sigma"].value = renderer.extinction(sim)
        bind_volume(p, sim, self.sampler, app.get_resource(Sun))
        frame.texture(DEPTH).use(5)
        try:
            frame.fullscreen(p)
        finally:
            unbind_volume(self.sampler)

    def release(self) -> None:
        if self.sampler is not None:
            self.sampler.release()
            self.sampler = None
