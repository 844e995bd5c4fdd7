"""A third-party effect written the way the README's "Writing a pass" shows: exponential height haze.

``HeightHazePlugin(density=2e-4, scale_height=300)`` adds one pass in the ``media`` phase that reads
the scene depth and blends the haze onto ``color``. Its GLSL lives beside this file and is found
through the shader search path under the prefix ``height_haze``.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from atmos import (COLOR, DEPTH, FullscreenPass, PassContext, Plugin, add_shader_path, bind_textures, set_camera_uniforms,
                   write_uniforms)
from atmos.checks import CheckedSettings, check_num, check_vec


@dataclass(frozen=True)
class HeightHazeSettings(CheckedSettings):
    """``density``: extinction (1/m) at ``base`` metres; ``scale_height``: metres over which it falls
    by e; ``max_distance``: metres of haze in front of the sky; ``haze_color``: linear RGB. All live."""
    density: float = 2e-4
    base: float = 0.0
    scale_height: float = 300.0
    max_distance: float = 20000.0
    haze_color: tuple = (0.7, 0.78, 0.9)

    def __post_init__(self):
        o = "HeightHazeSettings"
        self.store(dict(density=check_num(o, "density", self.density, 0.0),
                        base=check_num(o, "base", self.base),
                        scale_height=check_num(o, "scale_height", self.scale_height, 0.0, lo_open=True),
                        max_distance=check_num(o, "max_distance", self.max_distance, 0.0),
                        haze_color=check_vec(o, "haze_color", self.haze_color, 3, "non-negative")))


class HeightHazePass(FullscreenPass):
    name = "height_haze"
    phase = "media"                       # after the scene and the clouds, before post effects
    fragment = "height_haze/haze.frag"    # on the search path (see HeightHazePlugin.build)
    reads = (COLOR, DEPTH)                # it blends onto colour, so it reads it too
    writes = (COLOR,)

    def execute(self, frame: PassContext) -> None:
        s, p = self.plugin.settings, self.program
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_transmittance()       # rgb = light + T * rgb; the graph resets state after
        bind_textures(p, scene_depth=frame.resource(DEPTH))
        set_camera_uniforms(p, frame.view.camera, frame.view.aspect)
        write_uniforms(p, density=s.density, base=s.base, scale_height=s.scale_height,
                       max_distance=s.max_distance, haze_color=s.haze_color)   # skips what the compiler dropped
        frame.fullscreen(p)


class HeightHazePlugin(Plugin):
    """Exponential height haze: ``HeightHazePlugin(settings=None, **fields)`` with
    :class:`HeightHazeSettings`; ``configure(**changes)`` changes them on the next frame."""
    settings_class = HeightHazeSettings

    def build(self, app) -> None:
        add_shader_path(Path(__file__).parent, prefix="height_haze")
        app.graph.add_pass(HeightHazePass(self))
