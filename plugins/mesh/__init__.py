"""Your own geometry: instanced meshes drawn where their entities are.

An entity with a :class:`atmos.Transform` and a :class:`MeshInstance` is drawn (phase ``opaque``) with
its pose interpolated by ``clock.alpha``, lit by the ``Sun`` and the sky's ambient light, writing
``color`` (alpha 1) and ``depth`` — so cloud shadows, fog and clouds treat it like the terrain::

    crate = box((2, 2, 2))
    app.world.create_entity(Transform(position=(0, 5, 0)), MeshInstance(crate, color=(0.6, 0.4, 0.2)))

All instances of one :class:`Mesh` are one draw. GPU buffers of a mesh no entity uses for
``EVICT_FRAMES`` frames are released.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.checks import check_vec
from atmos.graph import PassContext
from atmos.plugin import Plugin
from atmos.plugins.mesh.geometry import Mesh, box, glider
from atmos.render_core import OpaquePass
from atmos.transform import Transform

__all__ = ["Mesh", "MeshInstance", "MeshPlugin", "box", "glider"]

EVICT_FRAMES = 120


@dataclass(slots=True)
class MeshInstance:
    """Draw ``mesh`` at the entity's Transform in ``color`` (linear RGB albedo, non-negative)."""
    mesh: Mesh
    color: tuple = (0.7, 0.7, 0.7)

    def __post_init__(self):
        if not isinstance(self.mesh, Mesh):
            raise ValueError(f"MeshInstance.mesh must be an atmos Mesh (Mesh(...), box(...), Mesh.load(path)), "
                             f"got {type(self.mesh).__name__}")
        self.color = check_vec("MeshInstance", "color", self.color, 3, "non-negative")


def collect_instances(world, alpha: float) -> dict:
    """{mesh: float32 (k, 19) rows of model matrix (column-major) and colour} for every entity with
    a Transform and a MeshInstance, posed ``alpha`` of the way from its last fixed step."""
    groups: dict = {}
    for entity, (transform, instance) in world.get_components(Transform, MeshInstance):
        m = transform.interpolated(alpha).matrix(transform.scale)
        groups.setdefault(instance.mesh, []).append((entity, np.concatenate([m.T.ravel(), instance.color])))
    out = {}
    for mesh, rows in groups.items():
        data = np.asarray([row for _, row in rows], np.float32)
        if not np.isfinite(data).all():
            bad = next(e for e, row in rows if not np.isfinite(row).all())
            raise ValueError(f"entity {bad}: its Transform is not finite (position, angles or scale), so its "
                             "MeshInstance cannot be drawn")
        out[mesh] = data
    return out


class MeshPass(OpaquePass):
    name = "meshes"

    def __init__(self, plugin: "MeshPlugin"):
        self.plugin = plugin
        self.program = None
        self.buffers: dict[int, list] = {}       # mesh id -> [vbo, ibo, instance buffer, vao, last frame used, vertices]
        self.frame = 0

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="mesh/mesh.vert", fragment_shader="mesh/mesh.frag")

    def _buffers(self, gpu, mesh: Mesh, rows: int) -> list:
        entry = self.buffers.get(mesh.id)
        if entry is None or entry[2].size < rows * 19 * 4:
            if entry is not None:
                self._release(mesh.id)
            ctx = gpu.ctx
            vbo = ctx.buffer(mesh.vertex_data)
            ibo = ctx.buffer(mesh.indices.tobytes())
            inst = ctx.buffer(reserve=max(rows, 16) * 2 * 19 * 4)     # room to grow
            vao = ctx.vertex_array(self.program, [(vbo, "3f 3f", "in_position", "in_normal"),
                                                  (inst, "16f 3f/i", "in_model", "in_color")],
                                   index_buffer=ibo, index_element_size=4)
            entry = self.buffers[mesh.id] = [vbo, ibo, inst, vao, 0, len(mesh.indices) * 3]
        entry[4] = self.frame
        return entry

    def execute(self, frame: PassContext) -> None:
        gpu = frame.gpu
        self.frame += 1
        self.begin(frame)
        for mesh, data in self.plugin.instances.items():
            _, _, inst, vao, _, vertices = self._buffers(gpu, mesh, len(data))
            inst.write(data.tobytes())
            vao.render(gpu.ctx.TRIANGLES, vertices=vertices, instances=len(data))
        for mesh_id in [k for k, e in self.buffers.items() if self.frame - e[4] > EVICT_FRAMES]:
            self._release(mesh_id)

    def _release(self, mesh_id: int) -> None:
        for obj in self.buffers.pop(mesh_id)[:4][::-1]:
            obj.release()

    def release(self) -> None:
        for mesh_id in list(self.buffers):
            self._release(mesh_id)


class MeshPlugin(Plugin):
    """Draws every entity with a Transform and a MeshInstance (pass "meshes"; needs TransformPlugin,
    in DefaultPlugins, for the interpolation). Collects them in the render stage ("collect_meshes")."""

    def __init__(self):
        super().__init__()
        self.instances: dict = {}
        self.mesh_pass: MeshPass | None = None

    def build(self, app) -> None:
        app.add_system(self.collect, "render", label="collect_meshes", before="frame_scheduler")
        if app.graph is not None:
            self.mesh_pass = MeshPass(self)
            app.graph.add_pass(self.mesh_pass)

    def collect(self, app) -> None:
        self.instances = collect_instances(app.world, app.clock.alpha)
