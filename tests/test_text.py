"""Text labels over the frame: the pixels of the reference blend of Pillow's coverage, placed by anchor;
a changed text re-rasterises, old ones are released; drawn above the frame-time overlay."""
import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.gpu import create_headless
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.text import CACHE, Label, TextPlugin, label_origin
from atmos.plugins.text.raster import rasterize
from atmos.plugins.text.reference import draw_label

W, H = 160, 90


def frame(gpu, *labels, overlay=False):
    app = App(gpu)
    text = TextPlugin()
    app.add_plugins(DefaultPlugins(overlay=overlay, fly_camera=False), SkyGradientPlugin(), text)
    for label in labels:
        app.world.create_entity(label)
    app.run_frames(1)
    pixels = gpu.read_pixels()
    assert gpu.ctx.error == "GL_NO_ERROR"
    return app, text, pixels


@pytest.mark.parametrize("anchor, x, y", [((0.0, 0.0), 6, 4), ((0.5, 0.5), 0, 0), ((1.0, 1.0), -3, -2),
                                          ((0.0, 0.0), -10, 80)])     # partly off the frame
def test_a_label_is_the_reference_blend_where_its_anchor_says(anchor, x, y):
    gpu = create_headless((W, H))
    try:
        label = Label("Score 42\nalt 300 m", x=x, y=y, size=18, color=(1.0, 0.8, 0.2, 0.9), anchor=anchor)
        app, _, with_text = frame(gpu, label)
        app.close()
        app, _, without = frame(gpu)
        app.close()
        coverage = rasterize(label.text, label.size)
        ox, oy = label_origin(label, coverage.shape, (W, H))
        want = draw_label(without, coverage, ox, oy, label.color)
        assert np.abs(with_text / 255.0 - want).max() <= 1.5 / 255
        assert np.abs(with_text.astype(int) - without).max() > 100, "the text shows"
        if anchor == (0.5, 0.5):
            assert abs(ox + coverage.shape[1] / 2 - W / 2) <= 1 and abs(oy + coverage.shape[0] / 2 - H / 2) <= 1
        from PIL import Image
        Image.fromarray(with_text).save(f"out/text_{anchor[0]}_{x}.png")
    finally:
        gpu.release()


def test_text_changes_reuse_the_cache_and_release_what_falls_out(gpu, ctx):
    app = App(gpu)
    text = TextPlugin()
    app.add_plugins(DefaultPlugins(overlay=True, fly_camera=False), text)    # overlay shown: both blend
    e = app.world.create_entity(Label("0"))
    for i in range(CACHE + 40):
        app.world.component_for_entity(e, Label).text = f"score {i}"
        app.update(1 / 60)
    assert len(text.text_pass.textures) == CACHE
    app.world.component_for_entity(e, Label).text = ""
    app.update(1 / 60)
    assert "text" in app.graph.compile().culled                             # nothing to draw: culled
    app.close()


def test_bad_labels_are_named():
    with pytest.raises(ValueError, match="Label.size must be a whole number 4..512"):
        Label("x", size=0)
    with pytest.raises(ValueError, match="Label.color must be 4 numbers in 0..1"):
        Label("x", color=(255, 0, 0, 1))
    with pytest.raises(ValueError, match="TextPlugin.font must be a TrueType/OpenType font file or None; cannot load"):
        TextPlugin(font=__file__)


def test_labels_laid_out_for_a_design_height_keep_their_size_relative_to_the_frame():
    """TextPlugin(design_height=90): at 320x180 a label is twice as tall and twice as far from its anchor
    as at 160x90, so a HUD keeps its place and size when the window grows."""
    boxes = {}
    for size in ((160, 90), (320, 180)):
        gpu = create_headless(size)
        try:
            def render(with_label):
                app = App(gpu).add_plugins(DefaultPlugins(fly_camera=False), SkyGradientPlugin(),
                                           TextPlugin(design_height=90))
                if with_label:
                    app.world.create_entity(Label("HUD 12", x=10, y=8, size=16))
                app.run_frames(1)
                pixels = gpu.read_pixels().astype(int)
                app.close()
                return pixels
            changed = np.abs(render(True) - render(False)).sum(-1) > 60
            rows, cols = np.nonzero(changed)
            boxes[size] = (rows.min(), rows.max(), cols.min(), cols.max())
        finally:
            gpu.release()
    (t1, b1, l1, r1), (t2, b2, l2, r2) = boxes[(160, 90)], boxes[(320, 180)]
    assert (b2 - t2) / (b1 - t1) == pytest.approx(2.0, abs=0.25) and (r2 - l2) / (r1 - l1) == pytest.approx(2.0, abs=0.25)
    assert l2 == pytest.approx(2 * l1, abs=3) and t2 == pytest.approx(2 * t1, abs=3)
    with pytest.raises(ValueError, match="TextPlugin.design_height must be a whole number 16..16384"):
        TextPlugin(design_height=0)
