"""FXAA: the shader against its float64 reference on fresh random images with edges; a flat image
passes unchanged; HDR extremes stay finite; in a scene the stair steps of a mesh's edges soften."""
import numpy as np
import pytest

from atmos import App, DefaultPlugins, MeshInstance, MeshPlugin, Transform, box
from atmos.gpu import create_headless
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_images, bind_textures, write_uniforms
from atmos.graph.compute import work_groups
from atmos.plugins.antialias import AntialiasPlugin, AntialiasSettings
from atmos.plugins.antialias.reference import fxaa
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

SETTINGS = AntialiasSettings()


def gpu_fxaa(gpu, image, settings=SETTINGS):
    """(h, w, 4) float64: ``antialias/fxaa.comp`` run once from ``image`` (an exact float32 texture) into a
    NaN-prefilled rgba16f image, as the pass writes the frame's colour (an unwritten pixel shows)."""
    import moderngl
    h, w = image.shape[:2]
    ctx = gpu.ctx
    program = gpu.program(compute_shader="antialias/fxaa.comp")
    source = ctx.texture((w, h), 4, np.ascontiguousarray(image, np.float32).tobytes(), dtype="f4")
    source.filter = (moderngl.NEAREST, moderngl.NEAREST)
    out = ctx.texture((w, h), 4, np.full((h, w, 4), np.nan, np.float16).tobytes(), dtype="f2")
    try:
        write_uniforms(program, span_max=settings.span_max, reduce_mul=settings.reduce_mul,
                       reduce_min=settings.reduce_min)
        bind_textures(program, source=source)
        bind_images(program, color_image=out)
        dispatch(program, *work_groups((w, h), (8, 8)))
        ctx.memory_barrier()
        return np.frombuffer(out.read(), np.float16).reshape(h, w, 4).astype(np.float64)
    finally:
        source.release()
        out.release()


F16_ULP = 2.0 ** -10    # rgba16f's relative step: a store rounds to nearest or (Mesa) toward zero, within one
F16_SUBNORMAL = 2.0 ** -24  # its absolute step below 2^-14, where the relative step no longer holds


def edgy(rng, h=37, w=53):
    """Random slanted edges through the image between random HDR colours, a little noise, random alpha.
    The colours' brightness levels differ (FXAA sees luma only: two colours of one luma make no edge), and
    every edge lies 15..75 degrees off the axes (an edge along an axis has no stair steps to soften)."""
    y, x = np.mgrid[0:h, 0:w]
    levels = rng.permutation([0.05, 0.5, 1.5, 4.0])
    image = np.zeros((h, w, 4))
    image[..., :3] = levels[0] * rng.uniform(0.6, 1.4, 3)
    for level in levels[1:]:
        angle = np.radians(rng.uniform(15.0, 75.0) + 90.0 * rng.integers(0, 4))
        a, c = np.array([np.cos(angle), np.sin(angle)]), level * rng.uniform(0.6, 1.4, 3)
        inside = a[0] * (x - rng.uniform(0.25, 0.75) * w) + a[1] * (y - rng.uniform(0.25, 0.75) * h) > 0
        image[inside, :3] = c
    image[..., :3] += rng.uniform(0, 0.05, (h, w, 3))
    image[..., 3] = rng.uniform(0, 1, (h, w))
    return image


def test_the_shader_matches_the_reference(gpu, ctx, rng):
    image = edgy(rng)
    got, want = gpu_fxaa(gpu, image), fxaa(image.astype(np.float32), SETTINGS.reduce_min, SETTINGS.reduce_mul,
                                           SETTINGS.span_max)
    # float32 arithmetic (1e-4) stored once as float16 (within one of its steps)
    close = (np.abs(got - want) <= F16_ULP * np.abs(want) + 1e-4).all(-1)
    # the one branch (keep the wider blur unless its luma leaves the range) may flip on a float32 tie
    assert close.mean() > 0.995, (1 - close.mean(), np.abs(got - want).max())
    np.testing.assert_allclose(got[..., 3], image[..., 3], rtol=F16_ULP, atol=F16_SUBNORMAL)  # alpha kept
    assert np.abs(want - image).max() > 0.1                                                 # it did something


def test_a_flat_image_is_unchanged_and_extremes_stay_finite(gpu, ctx, rng):
    flat = np.broadcast_to([0.3, 0.6, 0.9, 1.0], (9, 11, 4)).copy()
    np.testing.assert_allclose(gpu_fxaa(gpu, flat), flat, rtol=F16_ULP, atol=0)
    wild = edgy(rng) * np.array([1e4, 1e-30, 65504.0, 1.0])
    assert np.isfinite(gpu_fxaa(gpu, wild)).all()


def test_in_a_scene_the_stair_steps_of_edges_soften():
    gpu = create_headless((160, 90))
    try:
        def shot(*extra):
            app = App(gpu).add_plugins(DefaultPlugins(fly_camera=False), SkyGradientPlugin(), GroundPlugin(),
                                       MeshPlugin(), *extra)
            app.world.create_entity(Transform((0.0, 2.0, -8.0), yaw=0.5, roll=0.3), MeshInstance(box((3, 3, 3)),
                                                                                                (0.9, 0.2, 0.1)))
            app.run_frames(2)
            pixels = gpu.read_pixels().astype(float)
            app.close()
            return pixels
        plain, smooth = shot(), shot(AntialiasPlugin())
        def steps(img):   # the energy of jumps between neighbours: a hard step J counts J², two halves J²/2
            return (np.diff(img, axis=0) ** 2).sum() + (np.diff(img, axis=1) ** 2).sum()
        assert steps(smooth) < 0.8 * steps(plain), (steps(smooth), steps(plain))
        assert np.abs(smooth - plain).max() > 40
    finally:
        gpu.release()


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match="AntialiasSettings.span_max must be a finite number >= 1.0 and <= 16.0"):
        AntialiasPlugin(span_max=0.5)
