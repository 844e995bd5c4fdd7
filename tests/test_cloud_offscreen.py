"""Off-screen clouds at reduced resolution: the depth and composite draws against their float64
references on random inputs, and the whole sprite pass at downsample 2 and 4 against full resolution."""
from __future__ import annotations

import numpy as np
import pytest

from atmos.graph import PassBuilder, RenderGraph, RenderPass
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos import offscreen_reference as ref
from atmos.offscreen import CLOUD_COLOR, CLOUD_DEPTH, OffscreenLayer
from atmos.render_core import COLOR, DEPTH
from tests.test_cloud_render import BELOW, frame, look, save, scene

NEAR, FAR = 0.5, 8000.0


def random_depth(rng, size):
    """Window depths of a few planes and open sky (1.0), blocky so edges are few but present. Each
    plane has one depth, so equally near texels tie exactly and both sides take the first."""
    w, h = size
    levels = np.array([0.8, 0.97, 0.993, 0.9992, 1.0])   # no two texels nearly equally near a pixel
    coarse = rng.integers(0, len(levels), (h // 3 + 1, w // 3 + 1))
    return levels[np.repeat(np.repeat(coarse, 3, 0), 3, 1)[:h, :w]].astype(np.float32)


class OffscreenProbe(RenderPass):
    """Runs OffscreenLayer.begin, fills the low-res colour with given clouds, then end; keeps the low depth."""
    name = "probe"
    phase = "translucent"

    def __init__(self, size, factor, clouds):
        self.size, self.factor, self.clouds = size, factor, clouds
        self.low_depth = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(DEPTH)
        builder.read(COLOR)
        builder.write(COLOR)
        OffscreenLayer.declare(builder, self.size, self.factor)

    def prepare(self, gpu) -> None:
        self.offscreen = OffscreenLayer(gpu)

    def execute(self, frame) -> None:
        self.offscreen.begin(frame, self.factor)
        depth = frame.resource(CLOUD_DEPTH)
        self.low_depth = np.frombuffer(depth.read(), np.float32).reshape(depth.size[1], depth.size[0])
        frame.resource(CLOUD_COLOR).write(self.clouds.astype(np.float16).tobytes())
        self.offscreen.end(frame, self.factor, NEAR, FAR)


@pytest.mark.parametrize("size, factor", [((37, 23), 2), ((64, 40), 3), ((50, 31), 4), ((1, 1), 4)])
def test_depth_and_composite_match_the_references(fresh_gpu, rng, size, factor):
    gpu, ctx = fresh_gpu, fresh_gpu.ctx
    w, h = size
    depth = random_depth(rng, size)
    lw, lh = -(-w // factor), -(-h // factor)
    alpha = rng.uniform(0, 1, (lh, lw, 1))
    clouds = np.concatenate([rng.uniform(0, 1, (lh, lw, 3)) * alpha, alpha], -1)   # premultiplied
    background = rng.uniform(0, 1, (h, w, 4))
    color = ctx.texture((w, h), 4, background.astype(np.float32).tobytes(), dtype="f4")
    depth_texture = ctx.depth_texture((w, h), depth.tobytes())
    depth_texture.compare_func = ""
    gpu.resize(size)
    graph = RenderGraph(gpu)
    graph.import_resource(COLOR, color)
    graph.import_resource(DEPTH, depth_texture)
    probe = graph.add_pass(OffscreenProbe(size, factor, clouds))
    graph.execute()
    depth = np.frombuffer(depth_texture.read(), np.float32).reshape(h, w)      # as stored (24-bit)
    np.testing.assert_allclose(probe.low_depth, ref.far_depth(depth, factor), rtol=0, atol=1.2e-7)  # 2 ulp of 24 bits
    out = np.frombuffer(color.read(), np.float32).reshape(h, w, 4)
    up = ref.composite(clouds.astype(np.float16), probe.low_depth, depth, factor, NEAR, FAR)
    expected = up + (1.0 - up[..., 3:]) * background
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out, expected, atol=2e-5)
    graph.release()
    for t in (color, depth_texture):
        t.release()


def test_composite_keeps_edges_sharp():
    """A pixel of near geometry beside open sky takes the low-res texel that saw its depth."""
    depth = np.ones((4, 4), np.float32)
    depth[:, :2] = 0.5                                     # geometry on the left half
    low_depth = ref.far_depth(depth, 2)                    # [[0.5, 1], [0.5, 1]]
    clouds = np.zeros((2, 2, 4))
    clouds[:, 1] = (0.8, 0.8, 0.8, 0.8)                    # cloud only over the sky half
    up = ref.composite(clouds, low_depth, depth, 2, NEAR, FAR)
    assert (up[:, :2] == 0).all() and np.allclose(up[:, 2:, 3], 0.8)


def test_downsampled_clouds_match_full_resolution(gpu, ctx):
    app, renderer = scene(gpu, warmup=20)
    look(app, *BELOW)
    images = {}
    for factor in (1, 2, 4):
        renderer.configure(downsample=factor)
        images[factor] = frame(app, gpu)
        save(images[factor], f"cloud_offscreen_{factor}.png")
    renderer.configure(enabled=False)
    empty = frame(app, gpu)
    app.close()
    signal = np.sqrt(((images[1] - empty) ** 2).mean())
    assert signal > 5, "the clouds show"
    for factor in (2, 4):
        rmse = np.sqrt(((images[factor] - images[1]) ** 2).mean())
        assert rmse < 0.25 * signal, f"downsample {factor}: RMSE {rmse:.2f} against the clouds' {signal:.2f}"
        clear = (np.abs(images[1] - empty).max(-1) <= 1).all(1)     # rows the clouds leave alone at full res
        clear &= np.convolve(~clear, np.ones(2 * factor + 1), "same") == 0   # ... away from rows they touch
        assert clear.sum() >= 4
        assert np.abs(images[factor][clear] - empty[clear]).max() <= 1, "clouds bleed where they are hidden"


def test_downsample_allocates_only_when_used(fresh_gpu):
    gpu = fresh_gpu
    app, renderer = scene(gpu, warmup=2, downsample=1)
    app.update(1 / 60)
    assert CLOUD_COLOR not in app.graph.dump()
    renderer.configure(downsample=2)
    app.update(1 / 60)
    assert CLOUD_COLOR in app.graph.dump() and CLOUD_DEPTH in app.graph.dump()
    app.close()


@pytest.mark.parametrize("value", [0, 9, 1.5, True, "2"])
def test_bad_downsample_is_refused(value):
    with pytest.raises(ValueError, match=r"CloudRenderSettings\.downsample must be a whole number 1\.\.8"):
        CloudRenderPlugin(downsample=value)
    plugin = CloudRenderPlugin(downsample=2)
    with pytest.raises(ValueError, match="downsample"):
        plugin.configure(downsample=value)
    assert plugin.settings.downsample == 2
