"""Light shafts near the sun (thesis 7.3.2) as a screen-space effect: an occlusion mask of the bright
open sky near the sun (clouds and geometry cut it through the colour target's alpha, the sky
occlusion of :mod:`atmos.render_core`), blurred radially toward the sun and added on.

``LightShaftsPlugin`` adds the "light_shafts" pass; ``LightShaftSettings`` its settings;
``screen_sun`` where the sun is on screen and the fades; ``reference`` numpy float64 mask and blur.
"""
from atmos.plugins.light_shafts import reference
from atmos.plugins.light_shafts.settings import LightShaftSettings
from atmos.plugins.light_shafts.plugin import LightShaftsPass, LightShaftsPlugin, blur_uniforms
from atmos.plugins.light_shafts.screen_sun import ScreenSun, screen_sun

__all__ = ["LightShaftSettings", "LightShaftsPass", "LightShaftsPlugin", "ScreenSun", "blur_uniforms", "reference",
           "screen_sun"]
