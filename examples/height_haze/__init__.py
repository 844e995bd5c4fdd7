"""A third-party effect written the way the README's "Writing a pass" shows: exponential height haze.

``HeightHazePlugin(density=2e-4, scale_height=300)`` adds one compute pass in the ``media`` phase that
reads the scene depth and composites the haze onto ``color`` in place. Its GLSL lives beside this file
and is found through the shader search path under the prefix ``height_haze``.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from atmos import COLOR, DEPTH, ComputePass, PassContext, Plugin, add_shader_path, write_uniforms
from atmos.checks import CheckedSettings, num_field, vec_field


@dataclass(frozen=True)
class HeightHazeSettings(CheckedSettings):
    """Haze thinning with height (all live)."""
    density: float = num_field(2e-4, 0.0, doc="extinction (1/m) at height base")
    base: float = num_field(0.0, doc="m: where the haze has its full density")
    scale_height: float = num_field(300.0, 0.0, doc="m over which the density falls by e", lo_open=True)
    max_distance: float = num_field(20000.0, 0.0, doc="m of haze in front of the sky")
    haze_color: tuple = vec_field((0.7, 0.78, 0.9), 3, "non-negative", "linear RGB of the in-scattered light")


class HeightHazePass(ComputePass):
    name = "height_haze"
    phase = "media"                       # after the scene and the clouds, before post effects
    compute = "height_haze/haze.comp"     # on the search path (see HeightHazePlugin.build)
    reads = (COLOR, DEPTH)                # colour is read and written in place (an image)
    writes = (COLOR,)

    def execute(self, frame: PassContext) -> None:
        s, p = self.plugin.settings, self.program
        write_uniforms(p, density=s.density, base=s.base, scale_height=s.scale_height,
                       max_distance=s.max_distance, haze_color=s.haze_color)   # skips what the compiler dropped
        frame.dispatch(p, self.groups(frame.view.size), textures={"scene_depth": DEPTH}, images={"color_image": COLOR})


class HeightHazePlugin(Plugin):
    """Exponential height haze: ``HeightHazePlugin(settings=None, **fields)`` with
    :class:`HeightHazeSettings`; ``configure(**changes)`` changes them on the next frame."""
    settings_class = HeightHazeSettings

    def build(self, app) -> None:
        add_shader_path(Path(__file__).parent, prefix="height_haze")
        app.graph.add_pass(HeightHazePass(self))
