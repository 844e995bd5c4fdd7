"""TerrainPlugin and its pass: draws the heightfield into ``color`` and ``depth``."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, int_field, num_field
from atmos.graph import PassContext
from atmos.plugin import Plugin
from atmos.plugins.terrain.heightfield import height, heightfield, triangle_count
from atmos.render_core import OpaquePass


@dataclass(frozen=True)
class TerrainSettings(CheckedSettings):
    """A square heightfield of hills (all live: a change re-makes the mesh on the next frame)."""
    size: float = num_field(256.0, 0.0, doc="metres along each side of the square", lo_open=True)
    cells: int = int_field(71, 1, 1024, "quads along each side, cells² in all (2 triangles each; 71 → 10,082)")
    relief: float = num_field(30.0, doc="metres: the hills' height scale")

    def mesh_key(self) -> tuple:
        return self.size, self.cells, self.relief


class TerrainPass(OpaquePass):
    name = "terrain"

    def __init__(self, plugin: "TerrainPlugin"):
        self.plugin = plugin
        self.program = self.vao = self.vbo = self.ibo = None
        self.mesh_key = None

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="terrain/terrain.vert", fragment_shader="terrain/terrain.frag")
        self.make_mesh(gpu)

    def make_mesh(self, gpu) -> None:
        """(Re)make the mesh for the plugin's current settings."""
        self._release_mesh()
        s = self.plugin.settings
        vertices, indices = heightfield(s.size, s.cells, s.relief)
        self.mesh_key = s.mesh_key()
        self.vbo = gpu.track(gpu.ctx.buffer(vertices.tobytes()))
        self.ibo = gpu.track(gpu.ctx.buffer(indices.tobytes()))
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, [(self.vbo, "3f 3f", "in_position", "in_normal")],
                                                  index_buffer=self.ibo, index_element_size=4))

    def execute(self, frame: PassContext) -> None:
        gpu = frame.gpu
        self.begin(frame)
        if self.plugin.settings.mesh_key() != self.mesh_key:
            self.make_mesh(gpu)
        self.program["relief"].value = self.plugin.settings.relief
        self.vao.render(gpu.ctx.TRIANGLES)

    def _release_mesh(self) -> None:
        for obj in (self.vao, self.vbo, self.ibo):
            if obj is not None:
                obj.release()
        self.vao = self.vbo = self.ibo = None
        self.mesh_key = None

    def release(self) -> None:
        self._release_mesh()


class TerrainPlugin(Plugin):
    """The heightfield terrain: ``TerrainPlugin(settings=None, **fields)`` with :class:`TerrainSettings`;
    ``configure(**changes)`` changes any of them live (the mesh is re-made on the next frame)."""

    settings_class = TerrainSettings

    @property
    def triangles(self) -> int:
        return triangle_count(self.settings.cells)

    def height_at(self, x, z):
        """The ground's height (m) under world (x, z), from the same formula as the mesh (between its
        vertices the mesh is flat, so it may differ there by a little)."""
        s = self.settings
        return height(x, z, s.relief, s.size)

    def build(self, app) -> None:
        app.graph.add_pass(TerrainPass(self))
