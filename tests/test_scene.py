"""Whole scenes: what a scene leaves out costs nothing; long runs leak nothing; resizing is safe."""
import numpy as np
import pytest

from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.template_volume import TemplateVolumePlugin


def scene(gpu, *plugins):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), *plugins)
    app.startup()
    return app


def test_scene_without_an_effect_runs_compiles_and_allocates_none_of_it(fresh_gpu):
    app = scene(fresh_gpu)
    app.run_frames(3)
    dump = app.graph.dump()
    assert "template_volume" not in dump
    assert not any(f.startswith("template_volume/") for f in fresh_gpu.compiled_files)
    allocated = app.graph.pool.allocations
    app.close()

    app = scene(fresh_gpu, TemplateVolumePlugin(resolution=(16, 8, 16), slices=4))
    app.run_frames(3)
    assert "template_volume" in app.graph.dump()
    assert {"template_volume/density.comp", "template_volume/march.comp"} <= fresh_gpu.compiled_files
    assert app.graph.pool.allocations >= allocated
    app.close()


def test_long_run_allocates_nothing_per_frame(fresh_gpu):
    app = scene(fresh_gpu, TemplateVolumePlugin(resolution=(16, 8, 16), slices=4))
    app.run_frames(5)
    pool, tracked, programs = app.graph.pool.allocations, len(fresh_gpu._tracked), len(fresh_gpu._programs)
    app.run_frames(200)
    assert app.graph.pool.allocations == pool
    assert len(fresh_gpu._tracked) == tracked and len(fresh_gpu._programs) == programs
    app.close()


def test_volume_animates_through_the_three_sets(fresh_gpu):
    plugin = TemplateVolumePlugin(resolution=(16, 8, 16), slices=4)
    app = scene(fresh_gpu, plugin)
    seen = []
    for _ in range(12):
        app.update(1 / 30)
        a, b, t = plugin.job.view()
        seen.append((plugin.job.step, round(t, 3)))
    steps = [s for s, _ in seen]
    assert steps == sorted(steps) and steps[-1] - steps[0] == 3     # 12 frames, 4 slices per step
    assert sorted({t for _, t in seen}) == [0.0, 0.25, 0.5, 0.75]
    app.close()


@pytest.mark.parametrize("size", [(1, 1), (0, 0), (333, 77)])
def test_resize_including_minimized_window(fresh_gpu, size):
    app = scene(fresh_gpu)
    app.run_frames(1)
    fresh_gpu.resize(size)
    app.run_frames(2)
    img = fresh_gpu.read_pixels()
    assert img.shape[:2] == (max(1, size[1]), max(1, size[0])) and np.isfinite(img).all()
    app.close()
    fresh_gpu.resize((64, 40))


def test_two_apps_on_two_contexts_render_alternately():
    """moderngl never switches contexts itself; each App makes its own current for its frame."""
    gpus = [create_headless((48, 27)), create_headless((48, 27))]
    apps = [scene(g) for g in gpus]
    for _ in range(3):
        for app in apps:
            app.update(1 / 30)
    images = [g.read_pixels() for g in gpus]
    for app, g in zip(apps, gpus):
        assert g.ctx.error == "GL_NO_ERROR"
        app.close()
        g.release()
    assert images[0].std() > 5 and np.array_equal(images[0], images[1])
