"""Temporal anti-aliasing (AntialiasSettings.mode = "taa"): the resolve against its float64 twin on fresh
random frames, depths and camera moves; the geometry moves by exactly the jitter; a still view converges
to a supersampled one (and nearer than FXAA or none); a sliding mesh is followed by its own motion; the
jitter fills the pixel and stops with the mode; extremes stay finite; a resize restarts the history."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from atmos.camera import Camera, camera_matrices
from atmos.frame_constants import bind_frame
from atmos.gpu import create_headless
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_images, bind_textures, write_block
from atmos.lighting import Sun
from atmos.plugins.antialias import AntialiasPlugin, jitter_offset
from atmos.plugins.antialias.reference import taa_resolve
from atmos.plugins.antialias.temporal import TAA_BINDING, taa_block
from atmos.render_core import MOTION
from atmos.scene_view import FrameJitter

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_antialias import aim, scene, shown  # noqa: E402

F16 = 2.0 ** -11


def texture(ctx, data):
    data = np.ascontiguousarray(data)
    h, w = data.shape[:2]
    comps = 1 if data.ndim == 2 else data.shape[2]
    tex = ctx.texture((w, h), comps, data.tobytes(), dtype="f2" if data.dtype == np.float16 else "f4")
    return tex


def gpu_resolve(gpu, color, depth, history, camera, prev, blend, motion=None):
    """taa_resolve.comp on ``color`` (f16), ``depth`` (f32) and ``history`` (f16; None: none) for ``camera``
    over the previous ``prev`` camera, with the motion target ``motion`` (f32; None: the shader without
    MOTION); (h, w, 4) float64."""
    h, w = depth.shape
    bind_frame(gpu, camera, Sun(), (w, h))
    p = gpu.program(compute_shader="antialias/taa_resolve.comp", defines=None if motion is None else {"MOTION": 1})
    past = history if history is not None else np.zeros_like(color)
    textures = [texture(gpu.ctx, color), texture(gpu.ctx, depth), texture(gpu.ctx, past)]
    if motion is not None:
        textures.append(texture(gpu.ctx, motion))
    out = gpu.ctx.texture((w, h), 4, dtype="f2")
    try:
        write_block(p, "TemporalAA", TAA_BINDING, taa_block(camera_matrices(prev, w / h).gl("view_proj"), blend,
                                                            history is not None))
        bind_textures(p, color_in=textures[0], depth_in=textures[1], history=textures[2])
        if motion is not None:
            bind_textures(p, motion_in=textures[3])
        bind_images(p, resolved=out)
        dispatch(p, -(-w // 8), -(-h // 8))
        return np.frombuffer(out.read(), np.float16).reshape(h, w, 4).astype(np.float64)
    finally:
        for tex in (*textures, out):
            tex.release()


def random_frame(rng, h=41, w=67):
    """Slanted HDR edges with noise, depths in front (some sky at 1), alpha random."""
    y, x = np.mgrid[0:h, 0:w]
    color = np.zeros((h, w, 4))
    depth = np.full((h, w), 1.0)
    for _ in range(3):
        a = rng.uniform(-1, 1, 2)
        inside = a[0] * (x - rng.uniform(0, w)) + a[1] * (y - rng.uniform(0, h)) > 0
        color[inside, :3] = rng.uniform(0, 3, 3)
        depth[inside] = rng.uniform(0.98, 0.9995)
    color[..., :3] += rng.uniform(0, 0.05, (h, w, 3))
    color[..., 3] = rng.uniform(0, 1, (h, w))
    return color.astype(np.float16), depth.astype(np.float32)


def moved(rng, camera: Camera, scale: float) -> Camera:
    prev = Camera(position=camera.position + rng.normal(0, scale, 3), yaw=camera.yaw + rng.normal(0, 0.01 * scale),
                  pitch=camera.pitch + rng.normal(0, 0.01 * scale), near=camera.near, far=camera.far)
    return prev


def random_motion(rng, depth):
    """A motion target for ``depth``: per pixel a world motion (metres) tagged with the pixel's depth, with
    a depth a 24-bit step off, with one farther off (a surface drawn over it later), or none (-1)."""
    h, w = depth.shape
    motion = np.zeros((h, w, 4), np.float32)
    motion[..., :3] = rng.normal(0.0, 0.3, (h, w, 3))
    kind = rng.integers(0, 4, (h, w))
    motion[..., 3] = np.select([kind == 0, kind == 1, kind == 2],
                               [depth, depth + np.float32(2.0 ** -24), depth + np.float32(1e-4)], -1.0)
    return motion


@pytest.mark.parametrize("with_motion", [False, True], ids=["camera", "motion"])
def test_the_resolve_matches_its_float64_twin(gpu, rng, with_motion):
    color, depth = random_frame(rng)
    history = (color.astype(np.float64) * rng.uniform(0.5, 1.5, color.shape)).astype(np.float16)
    h, w = depth.shape
    cam = Camera(position=rng.uniform(-5, 5, 3), yaw=rng.uniform(-math.pi, math.pi), pitch=rng.uniform(-0.4, 0.4),
                 near=0.5, far=500.0)
    prev, blend = moved(rng, cam, 0.3), float(rng.uniform(0.05, 0.5))
    motion = random_motion(rng, depth) if with_motion else None
    got = gpu_resolve(gpu, color, depth, history, cam, prev, blend, motion)
    from atmos.camera import view_basis
    want = taa_resolve(color, depth, history, view_basis(cam, w / h), cam.position, cam.near, cam.far,
                       camera_matrices(prev, w / h).view_proj, blend, motion)
    if with_motion:                                             # the motion moved the history's reads
        still = taa_resolve(color, depth, history, view_basis(cam, w / h), cam.position, cam.near, cam.far,
                            camera_matrices(prev, w / h).view_proj, blend)
        assert np.abs(still - want).max() > 0.1
    # float32 reprojection and weights (a thousandth of a texel: 1/1024 of the texels' spread around),
    # float16 output; a point on the previous view's border may fall either side in float32 against float64
    pad = np.pad(history.astype(np.float64)[..., :3], ((1, 1), (1, 1), (0, 0)), mode="edge")
    stack = np.stack([pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    spread = stack.max(axis=0) - stack.min(axis=0)           # near where each pixel's history is read
    tol = spread.max(-1, keepdims=True) / 1024 + 2 * F16 * np.abs(want[..., :3]) + 1e-4
    ok = (np.abs(got[..., :3] - want[..., :3]) <= tol).all(-1)
    assert ok.mean() > 0.99, (1 - ok.mean(), np.abs(got - want)[..., :3].max())
    np.testing.assert_array_equal(got[..., 3], color[..., 3].astype(np.float64))       # alpha is this frame's
    assert np.abs(want - color).max() > 0.1, "the history took part"
    first = gpu_resolve(gpu, color, depth, None, cam, prev, blend)                       # no history: the frame
    np.testing.assert_array_equal(first, color.astype(np.float64))


def test_extremes_stay_finite(gpu, rng):
    color, depth = random_frame(rng)
    wild = (color.astype(np.float64) * np.array([2e4, 1e-7, 1.0, 1.0])).astype(np.float16)
    history = np.full_like(wild, 65504.0)
    cam = Camera(position=np.zeros(3), near=0.1, far=1e6)
    got = gpu_resolve(gpu, wild, depth, history, cam, moved(rng, cam, 50.0), 1e-3)
    assert np.isfinite(got).all()
    # a previous camera looking away: nothing of this view was in it, the frame stands alone
    away = Camera(position=np.zeros(3), yaw=math.pi, near=0.1, far=1e6)
    np.testing.assert_array_equal(gpu_resolve(gpu, color, depth, history, cam, away, 0.1), color.astype(np.float64))


def box_scene(gpu, *plugins):
    """benchmarks/bench_antialias.py's scene (a box over the ground plane), seen from 2 m up."""
    app, capture = scene(gpu, *plugins)
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 2.0, 0.0])
    cam.yaw, cam.pitch = 0.0, -0.05
    return app, capture


def test_the_geometry_moves_by_the_jitter():
    """FrameJitter (1, 0) draws the ground and a mesh one pixel to the right: the same depth a pixel over."""
    gpu = create_headless((96, 54))
    try:
        depths = []
        for jitter in ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)):
            app, capture = box_scene(gpu)
            app.insert_resource(FrameJitter(jitter))
            app.update(0.0)
            depths.append(capture.depth.copy())
            app.close()
        plain, right, up = depths
        assert (plain < 1.0).mean() > 0.3 and not np.array_equal(plain, right)
        # the rasteriser's depth plane of the (clipped, huge) ground triangles moves in float32: 8e-6 seen,
        # a hundredth of the depth's change from one row to the next
        for shifted, want in ((right[:, 1:], plain[:, :-1]), (up[1:, :], plain[:-1, :])):
            same = np.isclose(shifted, want, rtol=0, atol=2e-5)
            assert same.mean() > 0.995, 1 - same.mean()
            assert (np.abs(shifted - want) > 1e-3).mean() < (np.abs(plain - right) > 1e-3).mean() / 20
    finally:
        gpu.release()


def test_a_still_view_converges_to_a_supersampled_one():
    """The box over the ground, 24 still frames: nearer to a 4x4 supersampled frame (as displayed) than
    the frame without anti-aliasing, and than FXAA; the history's weight falls to ``history``."""
    w, h = 160, 90
    big = create_headless((4 * w, 4 * h))
    try:
        app, capture = box_scene(big)
        app.update(0.0)
        ref = shown(capture.color).reshape(h, 4, w, 4, 3).mean(axis=(1, 3))
        app.close()
    finally:
        big.release()
    gpu = create_headless((w, h))
    try:
        shots = {}
        for name, extra, frames in (("none", (), 1), ("fxaa", (AntialiasPlugin(),), 1),
                                    ("taa", (AntialiasPlugin(mode="taa"),), 24)):
            app, capture = box_scene(gpu, *extra)
            for _ in range(frames):
                app.update(0.0)
            shots[name] = shown(capture.color)
            if name == "taa":
                taa = next(p for p in app.graph.passes if p.name == "temporal_aa")
                assert taa.frames == 24 and taa.weight == pytest.approx(0.1)
            app.close()
    finally:
        gpu.release()
    err = {k: float(np.sqrt(np.mean((v - ref) ** 2))) for k, v in shots.items()}
    assert err["taa"] < 0.6 * err["none"] and err["taa"] < 0.5 * err["fxaa"], err      # seen: 0.51, 0.34


@pytest.mark.parametrize("slide, chase", [(0.04, False), (0.4, True)], ids=["sliding", "chasing"])
def test_a_moving_mesh_is_followed_by_its_own_motion(slide, chase):
    """The box slides half a pixel a frame past a still camera, or a chase camera follows it (the box still
    on screen, the world sweeping past): with the meshes' motion the frames stay near the supersampled
    ones (nearer than without anti-aliasing); reprojected by the camera alone, the box's history comes
    from where it was not (seen sliding: 1.52 %, 1.78 % none, 4.42 % without the motion; chasing: 1.05 %, 1.75 %, 2.35 %)."""
    w, h, frames = 160, 90, 16
    big = create_headless((4 * w, 4 * h))
    refs = []
    try:
        app, capture = scene(big)
        for n in range(frames):
            aim(app, n, 0.0, slide, chase)
            app.update(0.0)
            refs.append(shown(capture.color).reshape(h, 4, w, 4, 3).mean(axis=(1, 3)))
        app.close()
    finally:
        big.release()
    gpu = create_headless((w, h))
    err = {}
    try:
        for name, extra in (("none", ()), ("taa", (AntialiasPlugin(mode="taa"),)),
                            ("camera only", (AntialiasPlugin(mode="taa", motion=False),))):
            app, capture = scene(gpu, *extra)
            errors = []
            for n in range(frames):
                aim(app, n, 0.0, slide, chase)
                app.update(0.0)
                errors.append(np.sqrt(np.mean((shown(capture.color) - refs[n]) ** 2)) / refs[n].mean())
            assert (name == "taa") == (MOTION in app.graph.compile().resources)     # made only to be read
            app.close()
            err[name] = float(np.mean(errors[frames // 2:]))
    finally:
        gpu.release()
    assert err["taa"] < err["none"] and err["taa"] < 0.5 * err["camera only"], err


def test_a_failed_build_takes_its_motion_registration_out_again():
    """A MeshPlugin whose add_plugins call fails leaves no writer behind: the TAA does not wait for a motion
    target nobody makes (the graph still compiles and runs); added again, it draws the target."""
    from atmos import App, DefaultPlugins, MeshPlugin
    from atmos.plugin import Plugin
    from atmos.plugins.ground import GroundPlugin
    from atmos.plugins.sky_gradient import SkyGradientPlugin

    class Broken(Plugin):
        def build(self, app):
            raise RuntimeError("broken on purpose")
    gpu = create_headless((48, 27))
    try:
        app = App(gpu).add_plugins(DefaultPlugins(fly_camera=False), SkyGradientPlugin(), GroundPlugin(),
                                   AntialiasPlugin(mode="taa"))
        app.update(0.0)
        with pytest.raises(RuntimeError, match="broken on purpose"):
            app.add_plugins(MeshPlugin(), Broken())
        app.update(0.0)
        assert MOTION not in app.graph.compile().resources and gpu.ctx.error == "GL_NO_ERROR"
        app.add_plugins(MeshPlugin())
        app.update(0.0)
        assert MOTION in app.graph.compile().resources
        app.close()
    finally:
        gpu.release()


def test_the_mesh_motion_is_the_change_of_each_model_matrix():
    from atmos import MeshInstance, Transform, box
    from atmos.world import World
    from atmos.plugins.mesh import collect_instances
    world, crate = World(), box((1, 1, 1))
    still = world.create_entity(Transform((1.0, 2.0, 3.0), yaw=0.4), MeshInstance(crate))
    mover = world.create_entity(Transform((0.0, 0.0, 0.0)), MeshInstance(crate))
    previous = {}
    first = collect_instances(world, 1.0, previous)[crate]
    assert (first[:, 16:32] == 0).all() and set(previous) == {still, mover}          # a first frame: no motion
    world.component_for_entity(mover, Transform).teleport((0.5, 0.0, -2.0), yaw=0.1)
    rows = collect_instances(world, 1.0, previous)[crate]
    by_entity = dict(zip((still, mover), rows))
    assert (by_entity[still][16:32] == 0).all()
    change = by_entity[mover][16:32].reshape(4, 4).T            # column-major rows
    model = by_entity[mover][:16].reshape(4, 4).T
    np.testing.assert_allclose(change, model - first[1, :16].reshape(4, 4).T, atol=1e-6)
    world.delete_entity(mover, immediate=True)
    collect_instances(world, 1.0, previous)
    assert set(previous) == {still}                              # a deleted entity is let go


def test_the_jitter_fills_the_pixel_and_stops_with_the_mode():
    points = np.array([jitter_offset(n) for n in range(8)])
    assert (np.abs(points) < 0.5).all() and len({tuple(p) for p in points}) == 8
    assert np.array_equal(points, [jitter_offset(n + 8) for n in range(8)])          # it repeats
    for axis in range(2):                                       # each half of the pixel, on each axis
        assert 3 <= (points[:, axis] < 0).sum() <= 5
    gpu = create_headless((64, 36))
    try:
        plugin = AntialiasPlugin(mode="taa")
        app, _ = box_scene(gpu, plugin)
        app.update(0.0)
        app.update(0.0)
        assert app.resource(FrameJitter).pixels != (0.0, 0.0) and plugin.taa.frames == 2
        plugin.configure(mode="fxaa")
        app.update(0.0)
        assert app.resource(FrameJitter).pixels == (0.0, 0.0) and plugin.taa.frames == 0
        assert "temporal_aa" not in app.graph.compile().kept and "antialias" in app.graph.compile().kept
        plugin.configure(mode="none")
        app.update(0.0)
        kept = app.graph.compile().kept
        assert "temporal_aa" not in kept and "antialias" not in kept and app.resource(FrameJitter).pixels == (0.0, 0.0)
        plugin.configure(mode="taa")
        app.update(0.0)
        gpu.resize((80, 45))                                    # a new size: a new history
        app.update(0.0)
        assert plugin.taa.frames == 1 and gpu.ctx.error == "GL_NO_ERROR"
        app.close()
    finally:
        gpu.release()


def test_bad_mode_is_named():
    with pytest.raises(ValueError, match="AntialiasSettings.mode"):
        AntialiasPlugin(mode="msaa")
