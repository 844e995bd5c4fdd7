"""TerrainPlugin and its pass: draws the heightfield into ``color`` and ``depth``."""
from __future__ import annotations

from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.lighting import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.plugins.terrain.heightfield import heightfield, triangle_count
from atmos.render_core import COLOR, DEPTH


class TerrainPass(RenderPass):
    name = "terrain"

    def __init__(self, plugin: "TerrainPlugin"):
        self.plugin = plugin
        self.program = self.vao = self.vbo = self.ibo = None

    def setup(self, builder: PassBuilder) -> None:
        builder.write(COLOR)
        builder.write(DEPTH)

    def prepare(self, gpu) -> None:
        p = self.plugin
        self.program = gpu.program(vertex_shader="terrain/terrain.vert", fragment_shader="terrain/terrain.frag")
        vertices, indices = heightfield(p.size, p.cells, p.relief)
        self.vbo = gpu.track(gpu.ctx.buffer(vertices.tobytes()))
        self.ibo = gpu.track(gpu.ctx.buffer(indices.tobytes()))
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, [(self.vbo, "3f 3f", "in_position", "in_normal")],
                                                  index_buffer=self.ibo, index_element_size=4))

    def execute(self, frame: PassContext) -> None:
        app, gpu = frame.data["app"], frame.gpu
        frame.framebuffer(color=[COLOR], depth=DEPTH).use()
        gpu.ctx.enable(gpu.ctx.DEPTH_TEST)
        set_scene_uniforms(self.program, app, gpu.size[0] / gpu.size[1])
        self.program["relief"].value = self.plugin.relief
        self.vao.render(gpu.ctx.TRIANGLES)

    def release(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo):
            if obj is not None:
                obj.release()
        self.vao = self.vbo = self.ibo = None


class TerrainPlugin(Plugin):
    """A ``size`` metre square of ``cells``² quads (2 triangles each; 71 → 10,082) with ``relief`` metre hills."""

    def __init__(self, size: float = 256.0, cells: int = 71, relief: float = 30.0):
        heightfield(size, cells, relief)  # validates before anything is kept
        self.size, self.cells, self.relief = float(size), cells, float(relief)

    @property
    def triangles(self) -> int:
        return triangle_count(self.cells)

    def build(self, app) -> None:
        app.graph.add_pass(TerrainPass(self))
