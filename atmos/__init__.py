"""atmos: real-time atmospheric effects for Python games and demo scenes.

What a game or plugin author needs is importable from here, the effects included::

    from atmos import App, DefaultPlugins, SkyPlugin, CloudSky, TerrainPlugin, create_headless

Names load on first use, so ``import atmos`` stays cheap.
"""
from __future__ import annotations

from importlib import import_module

_EXPORTS = {
    # the App and plugins
    "App": "atmos.app", "AppError": "atmos.app", "Plugin": "atmos.plugin", "PluginGroup": "atmos.plugin",
    "DefaultPlugins": "atmos.defaults", "discover_plugins": "atmos.plugin",
    # plugin settings (the convention: atmos.checks)
    "CheckedSettings": "atmos.checks", "check_num": "atmos.checks", "check_int": "atmos.checks",
    "check_vec": "atmos.checks", "check_bool": "atmos.checks", "check_choice": "atmos.checks",
    "declared_rules": "atmos.checks", "Rule": "atmos.checks",
    "RenderCoreSettings": "atmos.render_core",
    # the sky's two models (SkySettings.model) and the physical one's atmosphere
    "SkyPlugin": "atmos.plugins.sky", "SkySettings": "atmos.plugins.sky", "AtmosphereSettings": "atmos.plugins.sky",
    # render passes and the graph
    "RenderPass": "atmos.graph", "FullscreenPass": "atmos.graph", "PassBuilder": "atmos.graph",
    "PassContext": "atmos.graph", "RenderGraph": "atmos.graph", "TextureDesc": "atmos.graph",
    "GraphError": "atmos.graph", "PHASES": "atmos.graph", "ComputePass": "atmos.graph", "BufferDesc": "atmos.graph",
    "work_groups": "atmos.graph", "dispatch": "atmos.gpu.hazards",
    "COLOR": "atmos.render_core", "DEPTH": "atmos.render_core", "SCREEN": "atmos.render_core",
    "CapturePass": "atmos.render_core", "OpaquePass": "atmos.render_core", "RenderCorePlugin": "atmos.render_core",
    # what passes see and write
    "SceneView": "atmos.scene_view", "Camera": "atmos.camera", "CameraPlugin": "atmos.camera_control",
    "set_camera_uniforms": "atmos.scene_uniforms", "Sun": "atmos.lighting", "GroundSurface": "atmos.lighting",
    "set_sun_uniforms": "atmos.scene_uniforms",
    "set_scene_uniforms": "atmos.scene_uniforms", "write_uniforms": "atmos.gpu.uniforms",
    "bind_textures": "atmos.gpu.uniforms", "bind_images": "atmos.gpu.uniforms", "bind_buffers": "atmos.gpu.uniforms",
    "bind_blocks": "atmos.gpu.uniforms",
    "FixedClock": "atmos.clock",
    # games: running, input, moving things and the camera
    "run": "atmos.runner", "DemoSettings": "atmos.demo_registry", "Input": "atmos.input",
    "InputPlugin": "atmos.input", "key": "atmos.keys", "mouse": "atmos.keys", "Transform": "atmos.transform",
    "Pose": "atmos.transform", "TransformPlugin": "atmos.transform", "FlyCameraPlugin": "atmos.camera_control",
    "ChaseCameraPlugin": "atmos.camera_control", "HostFramePlugin": "atmos.host_frame",
    # GPU
    "GpuContext": "atmos.gpu", "GpuError": "atmos.gpu", "ShaderError": "atmos.gpu",
    "create_headless": "atmos.gpu", "from_current": "atmos.gpu", "wrap_context": "atmos.gpu",
    "add_shader_path": "atmos.gpu.shaders",
    "GLMeter": "atmos.gpu.gl_meter", "GLCensus": "atmos.gpu.census", "camera_matrices": "atmos.camera", "CameraMatrices": "atmos.camera",
    # writing frames to files
    "OutputPlugin": "atmos.output", "FrameWriter": "atmos.output", "OutputError": "atmos.output",
    # work spread over frames
    "TextureSet": "atmos.slicing", "TripleSet": "atmos.slicing", "SlicedJob": "atmos.slicing",
    "SliceTask": "atmos.slicing", "FrameScheduler": "atmos.slicing",
    # the effects and game pieces (their own packages stay importable: atmos.plugins.<name>)
    "CloudSky": "atmos.plugins.clouds", "CloudsPlugin": "atmos.plugins.clouds", "CloudSettings": "atmos.plugins.clouds",
    "CloudRenderPlugin": "atmos.plugins.clouds.sprites", "RaymarchCloudsPlugin": "atmos.plugins.clouds.raymarch",
    "CloudTypeMap": "atmos.plugins.clouds.raymarch",
    "CloudFarFieldPlugin": "atmos.plugins.clouds.far_field", "CloudShadowsPlugin": "atmos.plugins.clouds.shadows",
    "WeatherPlugin": "atmos.plugins.clouds.weather", "DaylightPlugin": "atmos.plugins.daylight",
    "DaylightSettings": "atmos.plugins.daylight", "TimeOfDay": "atmos.plugins.daylight",
    "FogPlugin": "atmos.plugins.fog", "FogSettings": "atmos.plugins.fog",
    "VolumetricFogPlugin": "atmos.plugins.volumetric_fog", "LightShaftsPlugin": "atmos.plugins.light_shafts",
    "SkyGradientPlugin": "atmos.plugins.sky_gradient", "SkyLayerPlugin": "atmos.plugins.sky_layer",
    "GroundPlugin": "atmos.plugins.ground", "TerrainPlugin": "atmos.plugins.terrain",
    "TerrainSettings": "atmos.plugins.terrain", "MeshPlugin": "atmos.plugins.mesh", "Mesh": "atmos.plugins.mesh",
    "MeshInstance": "atmos.plugins.mesh", "TextPlugin": "atmos.plugins.text", "Label": "atmos.plugins.text",
    "AntialiasPlugin": "atmos.plugins.antialias", "PhysicalCameraPlugin": "atmos.plugins.physical_camera",
    "PhysicalCameraSettings": "atmos.plugins.physical_camera", "Sound": "atmos.sound", "Audio": "atmos.sound",
    "SoundPlugin": "atmos.sound",
    "box": "atmos.plugins.mesh", "sphere": "atmos.plugins.mesh", "cylinder": "atmos.plugins.mesh",
    "cone": "atmos.plugins.mesh", "capsule": "atmos.plugins.mesh", "torus": "atmos.plugins.mesh",
    "plane": "atmos.plugins.mesh", "revolve": "atmos.plugins.mesh", "mesh_bounds": "atmos.plugins.mesh",
    "raycast_instances": "atmos.plugins.mesh", "Parent": "atmos.transform", "world_matrix": "atmos.transform",
    # collisions (numpy, float64)
    "Hit": "atmos.collision", "ray_triangles": "atmos.collision", "ray_box": "atmos.collision",
    "ray_sphere": "atmos.collision", "ray_heightfield": "atmos.collision", "ray_grid": "atmos.collision",
    "segment": "atmos.collision", "sphere_sphere": "atmos.collision", "sphere_box": "atmos.collision",
    "box_box": "atmos.collision", "closest_point_box": "atmos.collision", "bounds": "atmos.collision",
    # game logic: timers, states, scripted play
    "Timer": "atmos.timers", "States": "atmos.states", "ScriptPlugin": "atmos.script",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'atmos' has no attribute {name!r}")
    value = getattr(import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
