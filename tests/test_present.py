"""The present pass: tone map against its float64 reference, the triangular dither before 8-bit
output (no banding in a shallow gradient, the mean unchanged), and exact 8-bit levels written, so the
image's own float -> 8-bit rounding (not round-to-nearest on every GPU) changes nothing."""
import numpy as np
import pytest

from atmos.app import App
from atmos.graph import RenderPass, work_groups
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.render_core import COLOR, DITHER_STEP, RenderCorePlugin, dither_offsets, present_levels, tone_map


class GradientPass(RenderPass):
    """Overwrites ``color`` with a given HDR image (rows bottom-up)."""
    name = "gradient"
    phase = "opaque"

    def __init__(self, image: np.ndarray):
        self.image = image

    def setup(self, builder) -> None:
        builder.write(COLOR)

    def execute(self, frame) -> None:
        frame.resource(COLOR).write(self.image.tobytes())


def present(gpu, image, **settings) -> np.ndarray:
    """uint8 (h, w, 3) screen, rows bottom-up, of the HDR ``image`` presented with ``settings``."""
    app = App(gpu).add_plugins(RenderCorePlugin(**settings))
    app.graph.add_pass(GradientPass(image))
    try:
        app.render()
        return gpu.read_pixels()[::-1]
    finally:
        app.close()


@pytest.fixture
def shallow_gradient(gpu):
    """A horizontal HDR ramp spanning only 6 steps of 8-bit output across the screen's width."""
    w, h = gpu.size
    hdr = np.linspace(0.10, 0.12, w)
    image = np.zeros((h, w, 4), np.float16)
    image[..., :3] = hdr[None, :, None]
    image[..., 3] = 1.0
    return image


def test_dither_offsets_are_triangular_and_unbiased():
    d = dither_offsets(256, 144)
    assert d.min() > -1.0 and d.max() < 1.0
    assert abs(d.mean()) < 0.005 and d.var() == pytest.approx(1 / 6, rel=0.02)
    hist, _ = np.histogram(d, bins=8, range=(-1, 1))
    expected = np.array([1, 3, 5, 7, 7, 5, 3, 1]) / 32 * d.size        # the triangle's mass per bin
    assert np.allclose(hist, expected, rtol=0.05)
    flat = d.reshape(-1, 3)
    assert np.abs(np.corrcoef(flat.T) - np.eye(3)).max() < 0.02, "channels dithered independently"
    assert abs(np.corrcoef(d[:, :-1, 0].ravel(), d[:, 1:, 0].ravel())[0, 1]) < 0.02, "neighbours independent"


def run_present(gpu, image: np.ndarray, fmt: str) -> np.ndarray:
    """(h, w, 4) float64 of ``core/present.comp`` run once over the float16 HDR ``image`` (rows bottom-up)
    into a NaN-prefilled image of ``fmt`` ("rgba32f": the values the shader stores; "rgba8": bytes / 255)."""
    ctx = gpu.ctx
    h, w = image.shape[:2]
    program = gpu.program(compute_shader="core/present.comp", defines={"PRESENT_FORMAT": fmt})
    hdr = ctx.texture((w, h), 4, np.ascontiguousarray(image, np.float16).tobytes(), dtype="f2")
    dtype = "f4" if fmt == "rgba32f" else "f1"
    out = ctx.texture((w, h), 4, np.full((h, w, 4), np.nan, np.float32).tobytes() if dtype == "f4" else None,
                      dtype=dtype)
    try:
        program["exposure"].value = 1.0
        program["dither"].value = DITHER_STEP
        bind_textures(program, hdr=hdr)
        bind_images(program, screen_image=out)
        dispatch(program, *work_groups((w, h), (8, 8)))
        data = out.read()
        if dtype == "f4":
            return np.frombuffer(data, np.float32).reshape(h, w, 4).astype(np.float64)
        return np.frombuffer(data, np.uint8).reshape(h, w, 4) / 255.0
    finally:
        hdr.release()
        out.release()


def test_present_matches_its_reference(gpu, ctx, shallow_gradient):
    out = present(gpu, shallow_gradient).astype(int)
    assert gpu.ctx.error == "GL_NO_ERROR"
    diff = np.abs(out - present_levels(shallow_gradient[..., :3].astype(np.float64)))
    # float32 (pow as exp2(y·log2 x): ~1e-6 relative on a GPU) against float64: values of at most 0.5
    # differ by ≤ 255 · 0.5 · 1e-6 = 1.3e-4 step, so only pixels that close to a tie (≤ 2.6e-4 of them)
    # may round to the neighbouring level
    assert diff.max() <= 1 and (diff == 0).mean() > 0.999


def round_to_nearest(v) -> np.ndarray:
    """float -> 8-bit as the GL prefers (and Mesa's llvmpipe does): the nearest level."""
    return np.floor(np.clip(v, 0.0, 1.0) * 255.0 + 0.5)


def nvidia_unorm8(v) -> np.ndarray:
    """float -> 8-bit as measured on a machine with an NVIDIA GPU (H200, driver 580): truncated to 12
    fractional bits, then rounded with ties down, floor((floor(v·4096)·255 + 2047) / 4096); values up
    to 1/16 step above a tie go down (3 % of uniform values). The measured level-by-level thresholds
    and the count of such values in a random sample agree with it."""
    return np.floor((np.floor(np.clip(v, 0.0, 1.0) * 4096.0) * 255.0 + 2047.0) / 4096.0)


def test_present_writes_exact_levels_that_any_rounding_keeps(gpu, ctx, rng):
    """The shader's own output (stored as float) is level / 255, so the nearest-level and NVIDIA's
    conversion give the same byte, the level of :func:`present_levels`, and the rgba8 image holds that
    byte; the unrounded values they would turn into different bytes (what the test would see without
    the rounding in the shader)."""
    w, h = 256, 64
    hdr = np.empty((h, w, 3))
    hdr[: h // 2] = np.geomspace(1e-4, 20.0, w)[None, :, None]           # every level once or more
    hdr[h // 2:] = rng.uniform(0.0, 2.0, (h - h // 2, w, 3))
    image = np.concatenate([hdr, np.ones((h, w, 1))], -1).astype(np.float16)
    out = run_present(gpu, image, "rgba32f")[..., :3]
    # level / 255.0 in float32: within 2.5 ulp (GLSL's division) of the level, ulp ≤ 2^-24 below 1
    assert np.abs(out * 255.0 - np.round(out * 255.0)).max() <= 255.0 * 2.5 * 2.0 ** -24
    assert np.array_equal(nvidia_unorm8(out), round_to_nearest(out))
    levels = present_levels(image[..., :3].astype(np.float64))
    assert (round_to_nearest(out) != levels).mean() < 1e-3        # ties, as in the test above
    assert np.array_equal(run_present(gpu, image, "rgba8")[..., :3] * 255.0, round_to_nearest(out))
    unrounded = tone_map(image[..., :3].astype(np.float64)) + DITHER_STEP * dither_offsets(w, h)
    assert (nvidia_unorm8(unrounded) != round_to_nearest(unrounded)).mean() > 0.01


def test_dither_removes_banding_and_keeps_the_mean(gpu, ctx, shallow_gradient):
    ideal = 255.0 * tone_map(shallow_gradient[0, :, :3].astype(np.float64))        # (w, 3) exact levels
    errors = {}
    for dither in (True, False):
        out = present(gpu, shallow_gradient, dither=dither).astype(np.float64)
        # what the eye averages (blocks of 8 columns, all rows): bands show as steps of up to ½
        blocks = out.reshape(out.shape[0], -1, 8, 3).mean(axis=(0, 2)) - ideal.reshape(-1, 8, 3).mean(axis=1)
        errors[dither] = np.abs(blocks).max()
        if dither:
            assert abs(out.mean() - ideal.mean()) < 0.02, "dithering changes no mean brightness"
            assert np.abs(out - ideal).max() <= 1.5, "noise of at most one step (plus rounding)"
    assert errors[True] < 0.1, f"banding left: columns off by up to {errors[True]:.2f} steps"
    assert errors[False] > 0.25, "without dither the same ramp bands (the test can fail)"


def test_hdr_max_is_one_number_in_python_and_glsl():
    """The cap on the light one effect adds (render_core.HDR_MAX, shaders/lib/hdr_max.glsl): 2^14, about a quarter of
    float16's 65504, so blends of values at most this stay finite on every driver."""
    import re
    from importlib.resources import files
    from atmos.render_core import HDR_MAX
    text = files("atmos.shaders").joinpath("lib", "hdr_max.glsl").read_text()
    assert float(re.search(r"const float HDR_MAX = ([0-9.e+]+);", text)[1]) == HDR_MAX == 2.0 ** 14


def test_a_multisampled_screen_gets_the_same_bytes(gpu, ctx, shallow_gradient):
    """A multisampled screen (some windows), which a framebuffer blit writes only from its own format
    (a window's RGB8 here, the image RGBA8), is drawn 1:1 instead: every sample gets the levels the
    blit gives a plain screen."""
    w, h = gpu.size
    plain = present(gpu, shallow_gradient)
    samples = ctx.renderbuffer((w, h), 3, samples=4)
    single = ctx.renderbuffer((w, h), 3)
    screen, resolved = ctx.framebuffer([samples]), ctx.framebuffer([single])
    target = gpu.target
    gpu.target = screen
    try:
        app = App(gpu).add_plugins(RenderCorePlugin())
        app.graph.add_pass(GradientPass(shallow_gradient))
        app.render()
        app.close()
        assert screen.samples == 4
        ctx.copy_framebuffer(resolved, screen)                          # resolve: the samples' mean
        out = np.frombuffer(resolved.read(components=3, alignment=1), np.uint8).reshape(h, w, 3)
        assert gpu.ctx.error == "GL_NO_ERROR"
    finally:
        gpu.target = target
        target.use()
        for obj in (screen, resolved, samples, single):
            obj.release()
    assert np.array_equal(out, plain)
