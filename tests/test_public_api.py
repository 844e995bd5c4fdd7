"""The public API: every name a game or plugin author needs comes from ``atmos``; it is typed."""
import importlib
import importlib.resources
import inspect
import typing

import pytest

import atmos


def test_every_public_name_imports_from_atmos():
    assert atmos.__all__ == sorted(atmos.__all__) and len(atmos.__all__) >= 30
    namespace = {}
    exec("from atmos import *", namespace)
    for name in atmos.__all__:
        assert namespace[name] is getattr(atmos, name), name
    for needed in ("App", "Plugin", "PluginGroup", "DefaultPlugins", "RenderPass", "FullscreenPass", "PHASES",
                   "COLOR", "DEPTH", "SCREEN", "Camera", "Sun", "SceneView", "create_headless"):
        assert needed in atmos.__all__
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        atmos.Nope


def test_the_effects_a_game_uses_come_from_atmos_and_load_on_first_use():
    import subprocess
    import sys
    for name, module in (("SkyPlugin", "atmos.plugins.sky"), ("CloudSky", "atmos.plugins.clouds"),
                         ("TerrainPlugin", "atmos.plugins.terrain"), ("FogPlugin", "atmos.plugins.fog"),
                         ("MeshPlugin", "atmos.plugins.mesh"), ("Label", "atmos.plugins.text"),
                         ("DaylightPlugin", "atmos.plugins.daylight"), ("VolumetricFogPlugin", "atmos.plugins.volumetric_fog")):
        assert getattr(atmos, name) is getattr(importlib.import_module(module), name), name   # the documented path too
    loaded = subprocess.run([sys.executable, "-c", "import atmos, sys; print(sorted(m for m in sys.modules "
                             "if m.startswith('atmos.plugins')))"], capture_output=True, text=True, check=True)
    assert loaded.stdout.strip() == "[]", "import atmos loaded effects before they were asked for"


def test_the_package_is_typed_and_extension_points_have_annotations():
    assert importlib.resources.files("atmos").joinpath("py.typed").is_file()
    for cls, methods in ((atmos.RenderPass, ("setup", "prepare", "execute", "release")),
                         (atmos.Plugin, ("build", "finish", "cleanup", "configure"))):
        for method in methods:
            signature = inspect.signature(getattr(cls, method))
            assert signature.return_annotation is not inspect.Signature.empty, f"{cls.__name__}.{method}"
    hints = typing.get_type_hints(atmos.RenderPass.execute)
    assert hints["frame"] is atmos.PassContext


def test_a_plugin_group_configures_its_members(gpu, ctx):
    from atmos.render_core import RenderCorePlugin
    group = atmos.DefaultPlugins(overlay=False).set(RenderCorePlugin(exposure=2.0))
    assert group.get(RenderCorePlugin).settings.exposure == 2.0
    group.configure(RenderCorePlugin, exposure=0.5)
    assert group.get(RenderCorePlugin).settings.exposure == 0.5
    with pytest.raises(ValueError, match="FogPlugin is not in DefaultPlugins"):
        from atmos.plugins.fog import FogPlugin
        group.set(FogPlugin())


def test_the_readme_scene_in_three_imports(gpu, ctx):
    from atmos import App, DefaultPlugins
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin())
    app.run_frames(1)
    assert gpu.read_pixels().std() > 1
    app.close()
