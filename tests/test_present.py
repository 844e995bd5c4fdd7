"""The present pass: tone map against its float64 reference, and the triangular dither before 8-bit
output (no banding in a shallow gradient, the mean unchanged)."""
import numpy as np
import pytest

from atmos.app import App
from atmos.graph import RenderPass
from atmos.render_core import COLOR, DITHER_STEP, RenderCorePlugin, dither_offsets, tone_map


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


def test_present_matches_its_reference(gpu, ctx, shallow_gradient):
    out = present(gpu, shallow_gradient).astype(int)
    h, w = out.shape[:2]
    ref = np.clip(tone_map(shallow_gradient[..., :3].astype(np.float64)) + DITHER_STEP * dither_offsets(w, h), 0, 1)
    diff = np.abs(out - np.round(ref * 255.0))
    assert diff.max() <= 1 and (diff == 0).mean() > 0.99


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
