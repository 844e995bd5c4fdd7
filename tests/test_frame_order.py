"""The frame's order comes from phases and data: any order of a demo's plugins compiles to the same
pass order and renders the same pixels."""
import numpy as np
import pytest

from atmos.app import App
from atmos.demo_registry import DemoSettings, list_demos
from atmos.gpu import create_headless
from atmos.plugin import PluginGroup
from atmos.runner import build_app

SIZE = (96, 54)


def render(name, monkeypatch, permute=None):
    """(pass order, pixels after 3 frames) of demo ``name``, its plugins added in ``permute``'s order."""
    original = App.add_plugins

    def add_plugins(self, *items):
        flat = [p for item in items for p in (item if isinstance(item, PluginGroup) else [item])]
        return original(self, *(permute(flat) if permute else flat))

    monkeypatch.setattr(App, "add_plugins", add_plugins)
    gpu = create_headless(SIZE)
    try:
        app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=3), gpu)
        app.run_frames(3, 1 / 30)
        order, pixels = app.graph.compile().kept, gpu.read_pixels()
        app.close()
        return order, pixels
    finally:
        gpu.release()
        monkeypatch.setattr(App, "add_plugins", original)


@pytest.mark.parametrize("name", sorted(list_demos()))
def test_plugin_order_changes_neither_the_passes_nor_the_pixels(name, monkeypatch, rng):
    order, pixels = render(name, monkeypatch)
    shuffled = lambda plugins: [plugins[i] for i in rng.permutation(len(plugins))]
    for permute in (lambda plugins: plugins[::-1], shuffled):
        other_order, other_pixels = render(name, monkeypatch, permute)
        assert other_order == order
        np.testing.assert_array_equal(other_pixels, pixels)


def test_swapping_sky_and_ground_in_the_readme_scene_changes_nothing(gpu, ctx):
    from atmos import App, DefaultPlugins
    from atmos.plugins.ground import GroundPlugin
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    images = []
    for plugins in ([SkyGradientPlugin(), GroundPlugin()], [GroundPlugin(), SkyGradientPlugin()]):
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), *plugins)
        app.run_frames(2)
        images.append(gpu.read_pixels())
        assert app.graph.compile().kept == ["clear", "sky_gradient", "ground", "present"]
        app.close()
    np.testing.assert_array_equal(images[0], images[1])
    assert images[0][-1].std() > 1 or images[0][-1].mean() != images[0][0].mean()   # ground below, sky above
