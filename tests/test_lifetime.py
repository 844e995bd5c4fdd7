"""Lifetime: App.close releases everything even when a plugin fails, use after close or after
gpu.release is a clear error, a failed build / finish / start-up leaves nothing half-applied, and no
cache keeps a released context alive."""
import gc
import weakref

import esper
import numpy as np
import pytest

from atmos.app import App, AppError
from atmos.defaults import DefaultPlugins
from atmos.gpu import GpuError, create_headless
from atmos.graph import RenderPass
from atmos.plugin import Plugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.render_core import COLOR


class Log(Plugin):
    """Records its cleanup; ``fail`` makes it raise there."""
    def __init__(self, log, fail=False):
        super().__init__()
        self.log, self.fail = log, fail

    def cleanup(self, app):
        self.log.append(self.name)
        if self.fail:
            raise RuntimeError(f"{self.name} cannot clean up")


class A(Log):
    pass


class B(Log):
    pass


class C(Log):
    pass


def scene(gpu, *plugins):
    return App(gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin(), *plugins)


def test_close_releases_everything_when_cleanups_fail_then_lists_the_failures(fresh_gpu):
    log = []
    app = scene(fresh_gpu, A(log), B(log, fail=True), C(log, fail=True))
    app.run_frames(2)
    assert app.graph.pool.textures > 0
    world = app.world.name
    with pytest.raises(AppError) as error:
        app.close()
    assert log == ["C", "B", "A"], "every plugin's cleanup ran, in reverse order"
    message = str(error.value)
    assert "2 step(s) failed" in message and "C.cleanup: RuntimeError: C cannot clean up" in message \
        and "B.cleanup: RuntimeError: B cannot clean up" in message
    assert app.graph.pool.textures == 0 and app.graph._frame.cached_framebuffers == 0, "the graph was released"
    assert world not in esper.list_worlds(), "the ECS world was closed"
    app.close()                                           # again: nothing, no error
    assert fresh_gpu.ctx.error == "GL_NO_ERROR"


@pytest.mark.parametrize("use", [
    lambda app: app.update(1 / 60), lambda app: app.render(), lambda app: app.run_frames(1),
    lambda app: app.startup(), lambda app: app.add_plugins(SkyGradientPlugin()),
    lambda app: app.add_system(lambda a: None), lambda app: app.insert_resource(object()),
], ids=["update", "render", "run_frames", "startup", "add_plugins", "add_system", "insert_resource"])
def test_use_after_close_is_a_clear_error(fresh_gpu, use):
    app = scene(fresh_gpu)
    app.run_frames(1)
    app.close()
    with pytest.raises(AppError, match=r"App\.\w+: this App was closed \(App.close\); build a new App"):
        use(app)


def test_gpu_release_closes_its_apps_first_and_a_second_release_does_nothing():
    gpu = create_headless((32, 18))
    log = []
    app = scene(gpu, A(log))
    app.run_frames(1)
    gpu.release()
    assert log == ["A"] and app.closed
    gpu.release()
    app.close()
    with pytest.raises(AppError, match=r"App.update: this App was closed \(by GpuContext.release\); build a new App"):
        app.update(1 / 60)


@pytest.mark.parametrize("use", [
    lambda gpu: gpu.read_pixels(), lambda gpu: gpu.resize((8, 8)), lambda gpu: gpu.make_current(),
    lambda gpu: gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="core/present_copy.frag"),
    lambda gpu: gpu.check(), lambda gpu: gpu.info(), lambda gpu: App(gpu),
], ids=["read_pixels", "resize", "make_current", "program", "check", "info", "App"])
def test_use_after_gpu_release_is_a_clear_error(use):
    gpu = create_headless((16, 16))
    gpu.release()
    with pytest.raises(GpuError, match=r"this GpuContext was released \(GpuContext.release\); create a new one"):
        use(gpu)


class Half(Plugin):
    """Registers a system, a pass, an import, a resource and a sliced job, then fails (``fail``)."""
    def __init__(self, fail):
        super().__init__()
        self.fail = fail
        self.cleaned = False

    def build(self, app):
        from atmos.plugins.template_volume import TemplateVolumePlugin
        app.add_system(lambda a: None, "update", label="half_system")
        app.graph.add_pass(HalfPass())
        app.graph.import_resource("half_import", object())
        app.insert_resource(HalfResource())
        app.add_plugins(TemplateVolumePlugin(resolution=(8, 8, 8), slices=2))   # a plugin its build adds
        if self.fail:
            raise ValueError("Half: bad build")

    def cleanup(self, app):
        self.cleaned = True


class HalfResource:
    pass


class HalfPass(RenderPass):
    name = "half"
    phase = "opaque"

    def setup(self, builder):
        builder.write(COLOR)

    def execute(self, frame):
        pass


def test_a_plugin_whose_build_failed_is_taken_out_with_what_it_registered(fresh_gpu):
    app = scene(fresh_gpu)
    app.run_frames(1)
    before = fresh_gpu.read_pixels()
    plugins, systems, jobs = [p.name for p in app.plugins], len(app.schedule.systems), len(app.frames.jobs)
    passes = {p.name for p in app.graph.passes}
    bad = Half(fail=True)
    with pytest.raises(ValueError, match="Half: bad build"):
        app.add_plugins(bad)
    assert bad.cleaned, "the failed plugin's cleanup ran (what it made is released)"
    assert [p.name for p in app.plugins] == plugins
    assert len(app.schedule.systems) == systems and {p.name for p in app.graph.passes} == passes
    assert "half_import" not in app.graph._imports and app.get_resource(HalfResource) is None
    assert len(app.frames.jobs) == jobs
    app.run_frames(1)
    assert np.array_equal(fresh_gpu.read_pixels(), before), "the App renders as before"
    app.add_plugins(Half(fail=False))                      # the corrected retry is not "added twice"
    assert app.get_resource(HalfResource) is not None and "half" in {p.name for p in app.graph.passes}
    app.run_frames(1)
    app.close()


def test_a_failed_finish_does_not_run_the_finished_plugins_again():
    calls = []

    class Good(Plugin):
        def finish(self, app):
            calls.append("good")

    class Flaky(Plugin):
        def finish(self, app):
            calls.append("flaky")
            if calls.count("flaky") == 1:
                raise RuntimeError("not yet")

    app = App().add_plugins(Good(), Flaky())
    with pytest.raises(RuntimeError, match="not yet"):
        app.startup()
    app.startup()
    assert calls == ["good", "flaky", "flaky"]
    app.close()


def test_a_failed_startup_leaves_the_app_unable_to_run_with_the_reason():
    finished = []

    class Boom(Plugin):
        def build(self, app):
            app.add_system(lambda a: 1 / 0, "startup", label="boom")

        def finish(self, app):
            finished.append(1)

    app = App().add_plugins(Boom())
    with pytest.raises(ZeroDivisionError):
        app.update(1 / 60)
    for use in (lambda: app.update(1 / 60), app.startup):
        with pytest.raises(AppError, match=r"start-up failed \(ZeroDivisionError: division by zero\); close it"):
            use()
    assert finished == [1], "finish ran once"
    app.close()


def test_no_cache_keeps_a_released_context_alive():
    """A context that ran clouds, shading, fog and the sky is garbage once released: no program,
    query or measure cache holds it (the shading cache once kept every context alive)."""
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds.weather.example import example_weather
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin
    from atmos.plugins.fog import FogPlugin
    from atmos.plugins.sky import SkyPlugin
    from atmos.plugins.clouds.light import compute_transmittance

    gpu = create_headless((48, 27))
    clouds = CloudsPlugin(CloudSettings(weather=example_weather((16, 8, 16), 10), smoothing_slices=2,
                                        group_size=(8, 8)), seed=1, warmup_steps=2)
    app = App(gpu).add_plugins(DefaultPlugins(), SkyPlugin(), GroundPlugin(), clouds, CloudRenderPlugin(),
                               FogPlugin(mode="hetero_exp", resolutions=(4, 8, 8, 8), tile_size=32.0))
    app.frames.time_budget_ms = 5.0                   # the GPU measure cache too
    app.run_frames(4)
    compute_transmittance(gpu, np.ones((4, 4, 4), np.float32), (0.0, 1.0, 0.0), 0.1)
    ctx, holder = weakref.ref(gpu.ctx), weakref.ref(gpu)
    app.close()
    gpu.release()
    del app, clouds, gpu
    gc.collect()
    assert holder() is None and ctx() is None, "a released context is still referenced"
