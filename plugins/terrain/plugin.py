"""TerrainPlugin and its pass: draws the heightfield into ``color`` and ``depth``."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_num, int_field, num_field
from atmos.collision import Hit, check_ray, height_normal, ray_grid
from atmos.graph import PassContext
from atmos.gpu.uniforms import write_uniforms
from atmos.lighting import GroundSurface
from atmos.plugin import Plugin
from atmos.plugins.terrain import material
from atmos.plugins.terrain.heightfield import height, terrain_mesh, triangle_count
from atmos.render_core import OpaquePass


@dataclass(frozen=True)
class TerrainSettings(CheckedSettings):
    """A square heightfield of hills continued to the horizon by a coarser far ring (all live: a
    change re-makes the mesh on the next frame)."""
    size: float = num_field(256.0, 0.0, doc="metres along each side of the square", lo_open=True)
    cells: int = int_field(71, 1, 1024, "quads along each side, cells² in all (2 triangles each; 71 → 10,082)")
    relief: float = num_field(30.0, doc="metres: the hills' height scale")
    horizon: float = num_field(150000.0, 0.0, 1e7, "metres from the origin to the edge of the far ring (the "
                               "hills continued around the square, each step outward heightfield.FAR_GROWTH "
                               "times wider); at most size/2: the square alone. The camera's far plane must "
                               "reach it: TerrainPlugin.far_plane()")
    snowline: float = num_field(1.0, doc="the height, in reliefs, above which flat ground is snow")
    rock_slope: float = num_field(0.3, 0.0, 1.0, "the slope (sine of its angle) where the ground is half grass, "
                                  "half rock (all rock 0.08 above)")

    def mesh_key(self) -> tuple:
        return self.size, self.cells, self.relief, self.horizon

    def collision_key(self) -> tuple:
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
        vertices, indices = terrain_mesh(s.size, s.cells, s.relief, s.horizon)
        self.mesh_key = s.mesh_key()
        self.vbo = gpu.track(gpu.ctx.buffer(vertices.tobytes()))
        self.ibo = gpu.track(gpu.ctx.buffer(indices.tobytes()))
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, [(self.vbo, "3f 3f", "in_position", "in_normal")],
                                                  index_buffer=self.ibo, index_element_size=4))

    def execute(self, frame: PassContext) -> None:
        gpu, s = frame.gpu, self.plugin.settings
        self.begin(frame)
        if s.mesh_key() != self.mesh_key:
            self.make_mesh(gpu)
        write_uniforms(self.program, relief=s.relief, snowline=s.snowline, rock_slope=s.rock_slope)
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
    ``configure(**changes)`` changes any of them live (the mesh is re-made on the next frame). Drawn:
    the square and its far ring, coloured by ``terrain/material.glsl``; the camera's far plane should
    be :meth:`far_plane`. Collision (:meth:`raycast`) is the square's."""

    settings_class = TerrainSettings
    _collision_grid: tuple | None = None          # (settings.collision_key(), float64 heights of the square)
    _mean_albedo: tuple | None = None             # (its key, RGB)

    @property
    def triangles(self) -> int:
        """Triangles of the near square (the far ring adds its own: :func:`terrain_mesh`)."""
        return triangle_count(self.settings.cells)

    def far_plane(self, within: float | None = None) -> float:
        """m: a camera far plane that shows all the drawn terrain from anywhere within ``within`` metres
        (horizontally) of the origin, up to 2·relief above the hills (None: anywhere over the square,
        size/√2): the distance to the ring's farthest corner, √2·horizon + within, plus 2·relief.
        With 24-bit depth and near n, the depth step at distance d ≫ n is about d² / (n 2^24) whatever
        the far plane (it only scales it by 1 − n / far), so the far ring costs the near view no
        precision (tests/test_terrain.py); far out the step is d / (n 2^24) of the distance (0.9 % at
        150 km with near 1 m): fog and haze by distance keep working."""
        s = self.settings
        within = s.size / math.sqrt(2.0) if within is None else check_num("TerrainPlugin.far_plane", "within",
                                                                            within, 0.0)
        return math.sqrt(2.0) * max(s.horizon, s.size / 2) + within + 2.0 * abs(s.relief)

    @property
    def mean_albedo(self) -> np.ndarray:
        """The area-weighted mean albedo (float64 RGB) of the near square by the drawn material
        (:func:`atmos.plugins.terrain.material.mean_albedo`): the ground's albedo for light bounced
        off it. Cached per settings."""
        s = self.settings
        key = (s.size, s.cells, s.relief, s.snowline, s.rock_slope)
        if self._mean_albedo is None or self._mean_albedo[0] != key:
            self._mean_albedo = (key, material.mean_albedo(*key))
        return self._mean_albedo[1].copy()

    def height_at(self, x, z):
        """The ground's height (m) under world (x, z), from the same formula as the mesh (between its
        vertices the mesh is flat, so it may differ there by a little)."""
        s = self.settings
        return height(x, z, s.relief, s.size)

    def normal_at(self, x, z) -> np.ndarray:
        """The ground's unit normal(s), shape (..., 3), under world (x, z) (arrays broadcast), from the
        height formula's slope (smooth, as the mesh's shading normals; a :meth:`raycast` hit carries
        the flat triangle's normal instead)."""
        s = self.settings
        return height_normal(self.height_at, x, z, eps=1e-4 * s.size)

    def raycast(self, origin, direction, max_distance=math.inf) -> Hit | None:
        """The first point where the ray meets the terrain as drawn (the flat triangles of the current
        settings' square, :func:`atmos.collision.ray_grid`): a :class:`~atmos.collision.Hit` with the
        distance, the point, the triangle's normal facing the ray and its number in :func:`heightfield`'s
        mesh, or None (beyond ``size``/2 there is no ground: the far ring is scenery). A ray starting at
        or under the ground over the terrain hits at distance 0. For a segment:
        ``atmos.collision.segment(terrain.raycast, a, b)``."""
        origin, direction, max_distance = check_ray("TerrainPlugin.raycast", origin, direction, max_distance)
        s = self.settings
        key = s.collision_key()
        if self._collision_grid is None or self._collision_grid[0] != key:
            axis = np.linspace(-s.size / 2, s.size / 2, s.cells + 1)     # heightfield()'s vertex heights
            x, z = np.meshgrid(axis, axis, indexing="ij")
            heights = height(x, z, s.relief, s.size).astype(np.float32).astype(np.float64)
            self._collision_grid = (key, heights)
        return ray_grid(origin, direction, self._collision_grid[1], s.size, max_distance)

    def build(self, app) -> None:
        app.graph.add_pass(TerrainPass(self))
        app.insert_resource(GroundSurface(lambda: self.mean_albedo))   # what the clouds' light from below sees
