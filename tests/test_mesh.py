"""Instanced meshes: lit like the reference, writing depth (so fog and cloud shadows apply), drawn where
their entities are (interpolated), loaded from files, and leaving no GPU buffers behind."""
import math

import numpy as np
import pytest

from atmos import App, Camera, DefaultPlugins, Sun, Transform
from atmos.gpu import create_headless
from atmos.plugins.fog import FogPlugin
from atmos.plugins.mesh import EVICT_FRAMES, Mesh, MeshInstance, MeshPlugin, box
from atmos.plugins.mesh.reference import mesh_color
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.render_core import CapturePass, RenderCorePlugin

W, H = 64, 48


def scene(gpu, *plugins):
    app = App(gpu)
    meshes = MeshPlugin()
    capture = CapturePass()
    app.insert_resource(Sun(direction=np.array([0.3, 0.8, 0.5]), color=(1.0, 0.9, 0.8), ambient=(0.2, 0.3, 0.4)))
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), SkyGradientPlugin(), meshes, *plugins)
    next(p for p in app.plugins if isinstance(p, RenderCorePlugin)).configure(dither=False)
    app.graph.add_pass(capture)
    cam = app.resource(Camera)
    cam.position, cam.yaw, cam.pitch, cam.roll = np.array([0.0, 0.0, 10.0]), 0.0, 0.0, 0.0
    return app, meshes, capture


def test_a_box_is_lit_like_the_reference_and_writes_depth():
    gpu = create_headless((W, H))
    try:
        app, _, capture = scene(gpu)
        app.world.create_entity(Transform(yaw=0.0), MeshInstance(box((4.0, 4.0, 4.0)), color=(0.8, 0.5, 0.3)))
        app.run_frames(1)
        color, depth = capture.color[::-1], capture.depth[::-1]
        centre = color[H // 2, W // 2]
        want = mesh_color((0.8, 0.5, 0.3), (0, 0, 1), (0.3, 0.8, 0.5), (1.0, 0.9, 0.8), (0.2, 0.3, 0.4))
        np.testing.assert_allclose(centre[:3], want, rtol=3e-3)      # the face toward the camera (+z)
        assert centre[3] == 1.0
        cam = app.resource(Camera)
        z = 8.0                                                       # the front face, 8 m from the camera
        n, f = cam.near, cam.far
        ndc = (f + n) / (f - n) - 2 * f * n / ((f - n) * z)
        assert depth[H // 2, W // 2] == pytest.approx(0.5 * ndc + 0.5, abs=1e-6)
        assert depth[2, 2] == 1.0 and color[2, 2, 3] == 0.0          # sky around it
        app.close()
    finally:
        gpu.release()


def test_instances_are_drawn_where_their_entities_are_and_deleted_ones_vanish():
    gpu = create_headless((W, H))
    try:
        app, meshes, capture = scene(gpu)
        crate = box((1.0, 1.0, 1.0))
        cam = app.resource(Camera)
        spots = [np.array([x, y, 0.0]) for x, y in ((-3.0, 1.5), (2.5, -1.0), (0.5, 2.0))]
        entities = [app.world.create_entity(Transform(position=p), MeshInstance(crate, (1.0, 1.0, 1.0))) for p in spots]
        app.run_frames(1)
        drawn = capture.depth[::-1] < 1.0

        def pixel(p):
            clip = cam.view_projection(W / H) @ np.append(p, 1.0)
            x, y = clip[:2] / clip[3]
            return int((1 - y) / 2 * H), int((x + 1) / 2 * W)

        assert all(drawn[pixel(p)] for p in spots) and drawn.mean() < 0.15
        assert len(meshes.instances[crate]) == 3
        app.world.delete_entity(entities[0])
        app.run_frames(1)
        assert not (capture.depth[::-1] < 1.0)[pixel(spots[0])] and len(meshes.instances[crate]) == 2
        app.close()
    finally:
        gpu.release()


def test_fog_covers_meshes_by_their_depth():
    gpu = create_headless((W, H))
    try:
        images = []
        for fog in ((), (FogPlugin(mode="exp", density=0.08, sky="keep"),)):
            app, _, capture = scene(gpu, *fog)
            app.world.create_entity(Transform(), MeshInstance(box((4.0, 4.0, 4.0)), color=(0.8, 0.1, 0.1)))
            app.run_frames(1)
            images.append(capture.color[::-1][H // 2, W // 2, :3].copy())
            app.close()
        clear, fogged = images
        fog_color = np.array([0.8, 0.8, 0.8])
        t = math.exp(-0.08 * 8.0)
        np.testing.assert_allclose(fogged, t * clear + (1 - t) * fog_color, atol=0.02)
    finally:
        gpu.release()


def test_unused_meshes_release_their_buffers_and_many_meshes_leak_nothing():
    gpu = create_headless((32, 24))
    try:
        app, meshes, _ = scene(gpu)
        for i in range(EVICT_FRAMES + 40):                           # a new mesh every frame, one entity each
            e = app.world.create_entity(Transform(), MeshInstance(box((1.0 + i, 1.0, 1.0))))
            app.run_frames(1)
            app.world.delete_entity(e)
        assert len(meshes.mesh_pass.buffers) <= EVICT_FRAMES + 1
        app.run_frames(EVICT_FRAMES + 2)
        assert meshes.mesh_pass.buffers == {} and gpu.ctx.error == "GL_NO_ERROR"
        app.close()
    finally:
        gpu.release()


def test_a_mesh_loads_from_an_obj_file(tmp_path):
    pytest.importorskip("trimesh")
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    mesh = Mesh.load(tmp_path / "tri.obj")
    assert mesh.indices.shape == (4, 3) and mesh.positions.shape == (12, 3)
    assert np.isclose(np.linalg.norm(mesh.normals, axis=1), 1).all()


@pytest.mark.parametrize("args, words", [((np.zeros((3, 2)), [[0, 1, 2]]), "positions must be a non-empty (n, 3)"),
                                         ((np.zeros((3, 3)), [[0, 1, 3]]), "indices must lie in 0..2"),
                                         ((np.zeros((3, 3)), [[0.0, 1.0, 2.0]]), "integer array")])
def test_bad_meshes_are_named(args, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
        Mesh(*args)
    with pytest.raises(ValueError, match="MeshInstance.mesh must be an atmos Mesh"):
        MeshInstance("crate")


def test_a_transform_gone_bad_is_named_before_the_frame(gpu, ctx):
    app, _, _ = scene(gpu)
    e = app.world.create_entity(Transform(), MeshInstance(box()))
    app.world.component_for_entity(e, Transform).position[1] = np.nan     # set in place by a game bug
    with pytest.raises(ValueError, match=f"entity {e}: its Transform is not finite"):
        app.run_frames(1)
    app.close()
