"""A cheap analytic sky: horizon-to-zenith gradient, a glow round the sun and its disc (the real sun's
size, limb-darkened, with glare: :mod:`atmos.sun_disc`). Draws the whole background."""
from dataclasses import dataclass

import numpy as np

from atmos.checks import vec_field
from atmos.composition import composition
from atmos.graph import ComputePass, PassContext
from atmos.gpu.uniforms import write_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.glsl_math import smoothstep
from atmos.sun_disc import SUN_DISC_DEFINES, SunDiscSettings, disc_chord, sun_disc


@dataclass(frozen=True)
class SkyGradientSettings(SunDiscSettings):
    """The gradient's sky colours, linear HDR, after the sun disc's fields (all live)."""
    zenith: tuple = vec_field((0.15, 0.35, 0.8), 3, "non-negative", "overhead")
    horizon: tuple = vec_field((0.75, 0.85, 1.0), 3, "non-negative", "at eye level")
    ground: tuple = vec_field((0.35, 0.33, 0.3), 3, "non-negative", "below the horizon")


def gradient_sky(view_dir, sun_dir, sun_color, settings: SkyGradientSettings | None = None,
                 pixel_angle: float = 0.0) -> np.ndarray:
    """(..., 3) float64: what the gradient pass writes for unit view directions ``view_dir`` (..., 3), the
    unit ``sun_dir`` and ``sun_color`` (``pixel_angle``: radians per pixel)."""
    p = settings or SkyGradientSettings()
    v = np.asarray(view_dir, np.float64)
    s = np.asarray(sun_dir, np.float64)
    up = v[..., 1:2]
    sky = np.asarray(p.horizon) + (np.asarray(p.zenith) - np.asarray(p.horizon)) * np.clip(up, 0.0, 1.0) ** 0.6
    sky = sky + (np.asarray(p.ground) - sky) * smoothstep(0.0, -0.08, up)
    day = float(smoothstep(-0.15, 0.1, s[1]))
    sky = sky * (0.05 + 0.95 * day)
    disc = sun_disc(v, s, (1.0, 1.0, 1.0), p.sun_size_deg, p.sun_gain, p.sun_glare, pixel_angle)
    glow = 0.25 * np.maximum(v @ s, 0.0)[..., None] ** 32
    return sky + np.asarray(sun_color, np.float64) * day * (glow + disc * (1.0 - smoothstep(0.0, -0.01, up)))


class SkyGradientPass(ComputePass):
    """The gradient where nothing was drawn (depth 1), one compute invocation per pixel
    (``sky_gradient/sky.comp``)."""
    name = "sky_gradient"
    phase = "sky"
    compute = "sky_gradient/sky.comp"
    reads = (DEPTH,)
    writes = (COLOR,)

    def defines(self) -> dict:
        return SUN_DISC_DEFINES

    def execute(self, frame: PassContext) -> None:
        settings, view, p = self.plugin.settings, frame.view, self.program
        write_uniforms(p, zenith=settings.zenith, horizon=settings.horizon, ground=settings.ground,
                       sun_look=(disc_chord(settings.sun_size_deg), settings.sun_gain, settings.sun_glare,
                                 view.camera.fov_y / max(1, view.size[1])))
        color = frame.image(COLOR)
        frame.dispatch(p, self.groups(color.size), textures={"scene_depth": DEPTH}, images={"color_image": color})


class SkyGradientPlugin(Plugin):
    """The gradient sky: ``SkyGradientPlugin(settings=None, **fields)`` with :class:`SkyGradientSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = SkyGradientSettings

    def build(self, app) -> None:
        app.graph.add_pass(SkyGradientPass(self))
        self.composition = composition(app)
        self.composition.backgrounds.add(SkyGradientPass.name)     # it writes every pixel after the depth clear

    def cleanup(self, app) -> None:
        comp = getattr(self, "composition", None)
        if comp is not None:
            comp.backgrounds.discard(SkyGradientPass.name)
