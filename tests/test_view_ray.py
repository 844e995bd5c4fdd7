"""lib/view_ray.glsl: view rays from the camera basis and distances from depth, against float64, at
far/near ratios where unprojecting through the inverse view-projection in float32 fails (1e11)."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera, view_basis
from atmos.scene_uniforms import set_camera_uniforms
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless, load_source
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.sky_layer import SkyLayerPlugin
from atmos.plugins.template_volume import TemplateVolumePlugin, VolumeBox
from atmos.plugins.volumetric_fog import VolumetricFogPlugin
from atmos.render_core import CapturePass
from fullscreen_probe import run_fullscreen

NONE = -7.0        # what the shader returns where nothing was drawn (depth 1)


def window_depth(camera: Camera, z):
    """float64 window-space depth of view depth ``z`` under ``camera.projection`` (GL, depth range 0..1)."""
    n, f = camera.near, camera.far
    return (1.0 / n - 1.0 / np.asarray(z, np.float64)) / (1.0 / n - 1.0 / f)


def pixel_ndc(size):
    w, h = size
    x, y = np.meshgrid((np.arange(w) + 0.5) / w * 2 - 1, (np.arange(h) + 0.5) / h * 2 - 1)
    return x, y


def reference_rays(camera: Camera, size) -> np.ndarray:
    """(h, w, 3) float64 rays with forward component 1, from the view matrix's rotation (rows right,
    up, -forward): view-space (x·tan(fov_x/2), y·tan(fov_y/2), -1) turned into the world."""
    w, h = size
    x, y = pixel_ndc(size)
    t = math.tan(camera.fov_y / 2)
    view_space = np.stack([x * t * w / h, y * t, -np.ones_like(x)], -1)
    return view_space @ camera.view()[:3, :3]          # R^T v for each v (R orthonormal)


def render_view_rays(gpu, camera: Camera, depth: np.ndarray) -> np.ndarray:
    """(h, w, 4) output of tests/data/shaders/view_ray.frag (unit direction, distance), the camera's
    uniforms set by set_camera_uniforms."""
    h, w = depth.shape

    def uniforms(prog):
        set_camera_uniforms(prog, camera, w / h)
        prog["none"].value = NONE
    return run_fullscreen(gpu, "test/view_ray.frag", (w, h), {"scene_depth": depth.astype(np.float32)}, uniforms, nearest=True)


@pytest.mark.parametrize("near, far", [(0.1, 1e10), (0.1, 2000.0), (1e-3, 1e12)])
def test_view_rays_and_distances_match_float64_at_huge_far_near_ratios(gpu, ctx, rng, near, far):
    size = (64, 36)
    w, h = size
    cam = Camera(position=rng.uniform(-1e4, 1e4, 3), yaw=rng.uniform(-math.pi, math.pi),
                 pitch=rng.uniform(-1.4, 1.4), fov_y=math.radians(rng.uniform(20, 110)), near=near, far=far)
    # view depths from the near plane to where float32 depth still tells them from 1, and some sky
    top = min(far, near * 2.0 ** 22)
    z = near * np.exp(rng.uniform(0.0, math.log(top / near), (h, w)))
    z[0, :8] = near
    depth = window_depth(cam, z).astype(np.float32)
    depth[1] = 1.0                                       # nothing drawn: `none`
    out = render_view_rays(gpu, cam, depth)
    assert np.isfinite(out).all(), "every pixel written, no NaN or inf"

    rays = reference_rays(cam, size)
    dirs = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
    assert np.abs(out[..., :3] - dirs).max() < 2e-6
    assert np.allclose(rays[..., :3], np.stack(pixel_ndc(size) + (np.ones((h, w)),), -1)
                       @ view_basis(cam, w / h).T, atol=1e-12)

    sky = depth >= 1.0
    assert np.all(out[sky, 3] == NONE)
    # exact: the distance of the depth actually stored (float32), in float64
    d = depth.astype(np.float64)
    stored_z = near / ((1.0 - d) + d * (near / far))
    want = stored_z * np.linalg.norm(rays, axis=-1)
    assert np.all(np.abs(out[~sky, 3] - want[~sky]) <= 2e-6 * want[~sky]), \
        np.max(np.abs(out[~sky, 3] / want[~sky] - 1))
    # and the true distance, within what rounding the depth to float32 allows
    true = z * np.linalg.norm(rays, axis=-1)
    ulp_bound = z * (2.0 ** -24) / np.maximum(1.0 - d, 2.0 ** -24) + 4e-6 * z
    assert np.all(np.abs(out[~sky, 3] - true[~sky]) <= ulp_bound[~sky] * np.linalg.norm(rays, axis=-1)[~sky])
    assert np.all(depth[0, :8] == 0.0)                   # the near plane
    assert np.allclose(out[0, :8, 3], near * np.linalg.norm(rays[0, :8], axis=-1), rtol=2e-6)


F32 = np.float32


def view_depth_as_written(depth, near, far) -> np.ndarray:
    """float32 numpy model of lib/view_ray.glsl's view_depth in its `precise` order:
    near / ((1 − depth) + depth · (near / far)), each operation rounded to float32."""
    d, n = np.asarray(depth, F32), F32(near)
    return n / ((F32(1.0) - d) + d * (n / F32(far)))


def view_depth_factored(depth, near, far) -> np.ndarray:
    """float32 numpy model of the same sum factored to 1 + depth · (near/far − 1) with one rounding
    (an fma), as GLSL lets a compiler evaluate it without `precise` and NVIDIA's does."""
    d, n = np.asarray(depth, F32), F32(near)
    k = n / F32(far) - F32(1.0)
    return n / (1.0 + d.astype(np.float64) * np.float64(k)).astype(F32)


@pytest.mark.parametrize("near, far", [(0.1, 1e10), (0.1, 2000.0), (1e-3, 1e12)])
def test_view_depth_is_precise_because_the_factored_sum_misses_the_tolerance(near, far):
    """The distance test above (2e-6 of the float64 distance of the stored depth) passes the order
    view_ray.glsl writes and fails the factored sum at far/near 2e4 and 1e11 (near/far − 1 loses
    near/far's low bits, or all of 1e-11), so the shader must keep its order: `precise`."""
    body = load_source("test/view_ray.frag").text.split("float view_depth(", 1)[1].split("\n}", 1)[0]
    assert "precise float" in body, "view_depth's sum is not `precise`: a compiler may factor it"
    cam = Camera(near=near, far=far)
    z = np.geomspace(near, min(far, near * 2.0 ** 22), 200001)
    d = window_depth(cam, z).astype(F32)
    d = d[d < 1.0]
    exact = near / ((1.0 - d.astype(np.float64)) + d * (near / far))
    as_written = np.abs(view_depth_as_written(d, near, far) / exact - 1.0).max()
    factored = np.abs(view_depth_factored(d, near, far) / exact - 1.0).max()
    assert as_written < 2e-6
    assert factored > 2e-6 if far / near < 1e13 else factored < 2e-6, factored


def test_float32_unprojection_fails_where_the_camera_basis_does_not():
    """Why view_ray.glsl does not unproject: at near 0.1, far 1e10 the float32 inverse view-projection
    maps every far-plane point to w = 0 (no direction at all) and is off by 1e-4..1e-2 on distances
    from depth, where view_depth's form, evaluated in float32, is off by at most an ulp."""
    cam = Camera(position=np.array([10.0, 20.0, 30.0]), yaw=0.7, pitch=0.2, near=0.1, far=1e10)
    x, y = pixel_ndc((16, 9))
    inv32 = np.linalg.inv(cam.view_projection(16 / 9)).astype(np.float32)
    far_points = np.stack([x, y, np.ones_like(x), np.ones_like(x)], -1).astype(np.float32) @ inv32.T
    assert np.all(far_points[..., 3] == 0.0)
    n, f = np.float32(cam.near), np.float32(cam.far)
    for z in (1e3, 1e5):
        d = np.float32(window_depth(cam, z))
        exact = cam.near / ((1.0 - float(d)) + float(d) * cam.near / cam.far)      # float64, of the stored depth
        hit = np.array([0.0, 0.0, 2 * d - 1, 1.0], np.float32) @ inv32.T
        unprojected = np.linalg.norm(hit[:3] / hit[3] - cam.position)              # on the centre ray: z
        basis = n / ((np.float32(1.0) - d) + d * (n / f))
        assert abs(unprojected / exact - 1) > 1e-4
        assert abs(basis / exact - 1) < 2e-7


def render_scene(size, near, far):
    """Every pass that builds view rays from depth, over sky and ground, at the camera planes given;
    returns the final HDR colour and depth (CapturePass)."""
    gpu = create_headless(size)
    probe = CapturePass()
    try:
        app = App(gpu).add_plugins(
            DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
            TemplateVolumePlugin(resolution=(16, 8, 16), slices=4, box=VolumeBox(center=(0.0, 6.0, -40.0))),
            VolumetricFogPlugin(center=(14.0, 1.0, -30.0), scale=(8.0, 2.0, 8.0), falloff=0.5, bias=0.3,
                                animate=False),
            SkyLayerPlugin(size=16, animate=False), LightShaftsPlugin())
        app.graph.add_pass(probe)
        app.startup()
        app.insert_resource(Sun(np.array([0.2, 0.25, -1.0])))
        cam = app.resource(Camera)
        cam.position = np.array([0.0, 4.0, 10.0])
        cam.yaw, cam.pitch, cam.near, cam.far = 0.1, -0.2, near, far
        app.run_frames(2, 1 / 30)
        assert gpu.ctx.error == "GL_NO_ERROR"
        color, depth = probe.color.copy(), probe.depth.copy()
        app.close()
        return color, depth
    finally:
        gpu.release()


def test_scene_passes_at_near_0_1_far_1e10_match_an_ordinary_far_plane():
    """Sky gradient, ground, template volume, volumetric fog, sky layer and light shafts with far/near =
    1e11: finite, and the same picture as with far 2000 wherever both drew the same surface."""
    size = (96, 54)
    color, depth = render_scene(size, 0.1, 1e10)
    ordinary, ordinary_depth = render_scene(size, 0.1, 2000.0)
    assert np.isfinite(color).all() and np.isfinite(depth).all()
    sky = (depth >= 1.0) & (ordinary_depth >= 1.0)
    ground = (depth < 1.0) & (ordinary_depth < 1.0)
    assert sky.mean() > 0.2 and ground.mean() > 0.2
    same = sky | ground
    diff = np.abs(color[same] - ordinary[same])
    assert np.percentile(diff, 99) < 2e-2 and diff.mean() < 2e-3, (diff.max(), diff.mean())
