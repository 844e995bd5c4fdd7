"""A large ground plane at height 0 with a procedural checker, lit by the sun, faded into the distance."""
import numpy as np

from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.lighting import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH


class GroundPass(RenderPass):
    name = "ground"

    def __init__(self, plugin: "GroundPlugin"):
        self.plugin = plugin
        self.program = self.vao = self.vbo = None

    def setup(self, builder: PassBuilder) -> None:
        builder.write(COLOR)
        builder.write(DEPTH)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="ground/ground.vert", fragment_shader="ground/ground.frag")
        h = self.plugin.half_size
        quad = np.array([[-h, -h], [h, -h], [-h, h], [h, h]], np.float32)
        self.vbo = gpu.track(gpu.ctx.buffer(quad.tobytes()))
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, [(self.vbo, "2f", "in_xz")]))

    def execute(self, frame: PassContext) -> None:
        app, gpu = frame.data["app"], frame.gpu
        frame.framebuffer(color=[COLOR], depth=DEPTH).use()
        gpu.ctx.enable(gpu.ctx.DEPTH_TEST)
        set_scene_uniforms(self.program, app, gpu.size[0] / gpu.size[1])
        self.program["albedo"].value = self.plugin.albedo
        self.program["tile"].value = self.plugin.tile
        self.vao.render(gpu.ctx.TRIANGLE_STRIP)

    def release(self) -> None:
        for obj in (self.vao, self.vbo):
            if obj is not None:
                obj.release()


class GroundPlugin(Plugin):
    """Ground plane of ``half_size`` metres each way; checker tiles of ``tile`` metres in ``albedo``."""

    def __init__(self, half_size: float = 4000.0, tile: float = 4.0, albedo=(0.28, 0.36, 0.2)):
        self.half_size, self.tile, self.albedo = half_size, tile, albedo

    def build(self, app) -> None:
        app.graph.add_pass(GroundPass(self))
