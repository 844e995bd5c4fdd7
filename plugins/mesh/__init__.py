"""Your own geometry: instanced meshes drawn where their entities are.

An entity with a :class:`atmos.Transform` and a :class:`MeshInstance` is drawn (phase ``opaque``) with
its pose interpolated by ``clock.alpha``, lit by the ``Sun`` and the sky's ambient light, writing
``color`` (alpha 1) and ``depth`` — so cloud shadows, fog and clouds treat it like the terrain::

    crate = box((2, 2, 2))
    app.world.create_entity(Transform(position=(0, 5, 0)), MeshInstance(crate, color=(0.6, 0.4, 0.2)))

Shapes: :func:`box`, :func:`sphere`, :func:`cylinder`, :func:`cone`, :func:`capsule`, :func:`torus`,
:func:`plane`, any profile turned about y (:func:`revolve`), files (:meth:`Mesh.load`). An entity
with a :class:`atmos.transform.Parent` is placed in its parent's frame (a basket under its balloon).

All instances of one :class:`Mesh` are one draw. GPU buffers of a mesh no entity uses for
``EVICT_FRAMES`` frames are released.

For game logic, :func:`mesh_bounds` gives a mesh's box (in world space under a Transform) and
:func:`raycast_instances` the first instance a ray meets (both at the Transform's current pose)::

    found = raycast_instances(app.world, origin, direction, max_distance=100.0)
    if found is not None:
        entity, hit = found          # an atmos.collision.Hit: distance, point, normal, triangle
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import check_vec
from atmos.collision import Hit, check_ray, bounds, ray_box, ray_triangles
from atmos.graph import PassContext
from atmos.plugin import Plugin
from atmos.plugins.mesh.geometry import Mesh, box, capsule, cone, cylinder, glider, plane, revolve, sphere, torus
from atmos.render_core import COLOR, DEPTH, MOTION, MOTION_NONE, OpaquePass, motion_desc, motion_targets
from atmos.transform import Parent, Transform, world_matrix

__all__ = ["Mesh", "MeshInstance", "MeshPlugin", "Parent", "box", "capsule", "cone", "cylinder", "glider", "mesh_bounds",
           "plane", "raycast_instances", "revolve", "sphere", "torus"]

EVICT_FRAMES = 120
ROW = 35                  # floats per instance: model matrix, its change since the last frame, colour
_NO_CHANGE = np.zeros(16)
_CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], np.float64)


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


def _model(transform) -> np.ndarray | None:
    if transform is None:
        return None
    if isinstance(transform, Transform):
        return transform.pose().matrix(transform.scale)
    return np.asarray(transform, np.float64)


def mesh_bounds(mesh: Mesh, transform=None) -> tuple[np.ndarray, np.ndarray]:
    """(box_min, box_max) of ``mesh``'s vertices: in model space, or in world space under
    ``transform`` (a :class:`atmos.Transform` at its current pose and scale, or a 4×4 model matrix)."""
    if not isinstance(mesh, Mesh):
        raise ValueError(f"mesh_bounds: mesh must be an atmos Mesh, got {type(mesh).__name__}")
    return bounds(mesh.positions, _model(transform))


def raycast_instances(world, origin, direction, max_distance=math.inf, ignore=()) -> tuple[int, Hit] | None:
    """(entity, :class:`~atmos.collision.Hit`) of the nearest mesh instance (entity with a Transform and
    a MeshInstance, at its current pose: what ``simulate`` systems see) the ray meets, or None;
    ``Hit.triangle`` is the row of ``mesh.indices``. Entities in ``ignore`` (e.g. the shooter) are
    skipped. Each instance's world box culls it before its triangles are tested (both faces)."""
    o, d, max_distance = check_ray("raycast_instances", origin, direction, max_distance)
    ignore = {ignore} if isinstance(ignore, (int, np.integer)) else set(ignore)
    best = None
    for entity, (transform, instance) in world.get_components(Transform, MeshInstance):
        if entity in ignore:
            continue
        m = world_matrix(world, entity)
        lo, hi = bounds(instance.mesh.positions)
        if ray_box(o, d, *bounds(lo + _CORNERS * (hi - lo), m), max_distance) is None:
            continue
        vertices = instance.mesh.positions @ m[:3, :3].T + m[:3, 3]
        hit = ray_triangles(o, d, vertices, instance.mesh.indices, max_distance)
        if hit is not None:
            best, max_distance = (entity, hit), hit.distance
    return best


def collect_instances(world, alpha: float, previous: dict | None = None) -> dict:
    """{mesh: float32 (k, 35) rows of model matrix, its change since the last frame (both column-major)
    and colour} for every entity with a Transform and a MeshInstance, posed ``alpha`` of the way from
    its last fixed step. ``previous`` (entity -> last frame's model matrix) gives the change, zero for an
    entity it lacks, and is updated to this frame's poses (the entities drawn now, no others)."""
    groups: dict = {}
    seen: dict = {}
    last = previous if previous is not None else {}
    for entity, (transform, instance) in world.get_components(Transform, MeshInstance):
        m = world_matrix(world, entity, alpha) if world.has_component(entity, Parent) else \
            transform.interpolated(alpha).matrix(transform.scale)
        before = last.get(entity)
        change = _NO_CHANGE if before is None else (m - before).T.ravel()
        seen[entity] = m
        groups.setdefault(instance.mesh, []).append((entity, np.concatenate([m.T.ravel(), change, instance.color])))
    out = {}
    for mesh, rows in groups.items():
        data = np.asarray([row for _, row in rows], np.float32)
        if not np.isfinite(data).all():
            bad = next(e for e, row in rows if not np.isfinite(row).all())
            raise ValueError(f"entity {bad}: its Transform is not finite (position, angles or scale), so its "
                             "MeshInstance cannot be drawn")
        out[mesh] = data
    if previous is not None:
        previous.clear()
        previous.update(seen)
    return out


class MeshPass(OpaquePass):
    """Draws the instances; while a reader wants it (:class:`atmos.render_core.MotionTargets`), also their
    motion since the last frame into :data:`~atmos.render_core.MOTION` (created here, cleared first)."""
    name = "meshes"

    def __init__(self, plugin: "MeshPlugin"):
        self.plugin = plugin
        self.program = None
        self.buffers: dict[int, list] = {}       # mesh id -> [vbo, ibo, instance buffer, vao, last frame used, vertices]
        self.frame = 0

    def setup_key(self) -> tuple:
        wanted = self.plugin.motion.wanted
        return (True, self.plugin.gpu.size) if wanted else (False,)

    def setup(self, builder) -> None:
        super().setup(builder)
        if self.plugin.motion.wanted:
            builder.create(MOTION, motion_desc(self.plugin.gpu.size))

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="mesh/mesh.vert", fragment_shader="mesh/mesh.frag")

    def _buffers(self, gpu, mesh: Mesh, rows: int) -> list:
        entry = self.buffers.get(mesh.id)
        if entry is None or entry[2].size < rows * ROW * 4:
            if entry is not None:
                self._release(mesh.id)
            ctx = gpu.ctx
            vbo = ctx.buffer(mesh.vertex_data)
            ibo = ctx.buffer(mesh.indices.tobytes())
            inst = ctx.buffer(reserve=max(rows, 16) * 2 * ROW * 4)     # room to grow
            vao = ctx.vertex_array(self.program, [(vbo, "3f 3f", "in_position", "in_normal"),
                                                  (inst, "16f 16f 3f/i", "in_model", "in_change", "in_color")],
                                   index_buffer=ibo, index_element_size=4)
            entry = self.buffers[mesh.id] = [vbo, ibo, inst, vao, 0, len(mesh.indices) * 3]
        entry[4] = self.frame
        return entry

    def execute(self, frame: PassContext) -> None:
        gpu = frame.gpu
        self.frame += 1
        self.begin(frame)
        if frame.declares(MOTION):
            frame.framebuffer(color=[MOTION]).clear(*MOTION_NONE)
            frame.framebuffer(color=[COLOR, MOTION], depth=DEPTH).use()
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
        self.previous: dict = {}           # entity -> its model matrix in the last frame drawn
        self.mesh_pass: MeshPass | None = None

    def build(self, app) -> None:
        app.add_system(self.collect, "render", label="collect_meshes", before="frame_scheduler")
        if app.graph is not None:
            self.gpu = app.gpu
            self.motion = motion_targets(app)
            self.mesh_pass = MeshPass(self)
            self.motion.writers.add(self.mesh_pass.name)
            app.graph.add_pass(self.mesh_pass)

    def cleanup(self, app) -> None:
        motion = getattr(self, "motion", None)
        if motion is not None and self.mesh_pass is not None:
            motion.writers.discard(self.mesh_pass.name)

    def collect(self, app) -> None:
        self.instances = collect_instances(app.world, app.clock.alpha, self.previous)
