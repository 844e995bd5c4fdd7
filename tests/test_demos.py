"""Every demo renders a few headless frames that are not blank (the CLI tests cover the file output)."""
import numpy as np
import pytest

from atmos.demo_registry import DemoSettings, list_demos
from atmos.gpu import create_headless
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.runner import build_app


@pytest.mark.parametrize("name", sorted(list_demos()))
def test_demo_renders_frames(name):
    gpu = create_headless((96, 54))
    try:
        app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=3), gpu)
        app.run_frames(4, 1 / 30)
        image = gpu.read_pixels().astype(float)
        assert gpu.ctx.error == "GL_NO_ERROR"
        assert image.std() > 3, f"demo {name} renders a blank image"
        app.close()
    finally:
        gpu.release()


def kept(app) -> set:
    return set(app.graph.compile().kept)


@pytest.mark.parametrize("name", ["sunset", "flight", "weather"])
def test_cloud_demos_march_by_default_render_with_sprites_and_key_c_switches_the_renderer(name):
    from atmos.demos._cloudscape import cloud_renderer
    from atmos.input import Input
    from atmos.keys import key
    gpu = create_headless((64, 40))
    try:
        app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=2), gpu, start=False)
        assert cloud_renderer(app) == "march"           # the default
        app.close()
        app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=2, clouds="sprites"), gpu)
        app.run_frames(2, 1 / 30)
        image = gpu.read_pixels().astype(float)
        assert gpu.ctx.error == "GL_NO_ERROR"
        assert image.max() > 20 and image.std() > 3, f"demo {name} with the sprites renders a blank image"
        assert cloud_renderer(app) == "sprites"
        march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
        assert "cloud_render" in kept(app) and not march.settings.volume    # the march: the far field alone
        assert "cloud_raymarch" in kept(app) and "cloud_far_field" not in kept(app)   # no 2D far-field pass
        inp = app.resource(Input)
        sprites = next(p for p in app.plugins if isinstance(p, CloudRenderPlugin))
        splats = sprites.splats()
        inp.press(key.X)                                # the sprites' splat flips (compute, points)
        app.update(1 / 30)
        inp.release(key.X)
        assert sprites.splats() is not splats and gpu.ctx.error == "GL_NO_ERROR"
        assert splats or sprites.sprite_pass.splat is not None          # turned on: the splat ran
        assert np.abs(gpu.read_pixels().astype(float) - image).mean() < 10, "the same clouds either way"
        inp.press(key.C)
        app.update(1 / 30)
        inp.release(key.C)
        assert cloud_renderer(app) == "march"
        assert "cloud_raymarch" in kept(app) and "cloud_render" not in kept(app)
        app.update(1 / 30)                          # held, not pressed again: no flip
        assert cloud_renderer(app) == "march"
        app.close()
    finally:
        gpu.release()


@pytest.mark.parametrize("name", ["sunset", "flight"])
def test_hazy_demos_take_the_air_the_fog_or_both(name):
    """``haze="air"``: the physical sky's aerial perspective hazes terrain and clouds, no fog pass runs;
    ``"both"``: the fog and the air mixed along each ray; the light shafts' froxel apply composites them (no
    fog or aerial pass, no media targets); each frame differs from the fog's and is not blank."""
    gpu = create_headless((96, 54))
    images = {}
    try:
        for haze in ("fog", "air", "both"):
            app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=2, haze=haze), gpu)
            app.run_frames(2, 1 / 30)
            images[haze] = gpu.read_pixels().astype(float)
            assert gpu.ctx.error == "GL_NO_ERROR"
            passes = kept(app)
            assert "light_shafts" in passes and "aerial_perspective" not in passes and "fog" not in passes, \
                "the shafts' froxel apply composites the fog and the air"
            assert "media_clear" not in passes and "media_light" not in app.graph.compile().resources
            app.close()
    finally:
        gpu.release()
    for haze in ("air", "both"):
        assert images[haze].max() > 20 and images[haze].std() > 3, f"{name} with {haze} renders a blank image"
        assert abs(images[haze] - images["fog"]).mean() > 1.0, "the haze changes the image"


def test_demo_settings_name_the_cloud_renderers():
    with pytest.raises(ValueError, match="DemoSettings.clouds must be one of 'sprites', 'march', got 'voxels'"):
        DemoSettings(clouds="voxels")
    with pytest.raises(ValueError, match="DemoSettings.haze must be one of 'fog', 'air', 'both', got 'smoke'"):
        DemoSettings(haze="smoke")
    for haze in ("air", "both"):
        with pytest.raises(ValueError, match=f"haze '{haze}' is the physical sky's aerial perspective: it needs sky='physical'"):
            DemoSettings(sky="preetham", haze=haze)
