"""The sky shader's defines and uniforms, shared by the sky pass and a compute evaluation of it."""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

import atmos.plugins.sky.stars as stars
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.preetham import COS_FLOOR, unit_vectors
from atmos.gpu.uniforms import bind_buffers, write_uniforms
from atmos.gpu.hazards import dispatch
from atmos.sun_disc import SUN_DISC_DEFINES, disc_chord

DAY_FADE = (-0.2, 0.02)      # sun height (sin elevation): night below the first, full Preetham day above the second
GROUND_DIM = 0.3
BELOW_FADE = 0.1
OZONE_DEPTH = (0.0097, 0.0282, 0.0013)    # vertical optical depth of the ozone layer (Chappuis band; red, green, blue)
OZONE_SHELL = 0.0069                      # 2 h / R: the layer's height h ≈ 22 km over the earth's radius
OZONE_BELOW = 10.0                        # growth of the path per unit of the sun's depth below the horizon


@lru_cache(maxsize=1)
def sky_defines() -> dict:
    """The constants of the float64 reference, handed to the GLSL as defines (one source of truth).
    Made once (the sky pass asks every frame): the same dict each time, not to be changed."""
    return {"SKY_COS_FLOOR": repr(COS_FLOOR), "DAY_LO": repr(DAY_FADE[0]), "DAY_HI": repr(DAY_FADE[1]),
            "GROUND_DIM": repr(GROUND_DIM), "BELOW_FADE": repr(BELOW_FADE),
            "OZONE_DEPTH": "vec3({}, {}, {})".format(*OZONE_DEPTH), "OZONE_SHELL": repr(OZONE_SHELL),
            "OZONE_BELOW": repr(OZONE_BELOW), **SUN_DISC_DEFINES,
            "STAR_GRID": stars.STAR_GRID, "STAR_KEY_A": f"{stars.STAR_KEY[0]}u", "STAR_KEY_B": f"{stars.STAR_KEY[1]}u",
            "STAR_SIGMA": repr(stars.STAR_SIGMA), "STAR_SIGMA_MAX": repr(stars.STAR_SIGMA_MAX),
            "STAR_FOOTPRINT": repr(stars.FOOTPRINT),
            "STAR_CUT_LO": repr(stars.STAR_CUT[0]), "STAR_CUT_HI": repr(stars.STAR_CUT[1]),
            "STAR_NIGHT_LO": repr(stars.STAR_NIGHT[0]), "STAR_NIGHT_HI": repr(stars.STAR_NIGHT[1]),
            "STAR_HORIZON": repr(stars.STAR_HORIZON),
            "TWINKLE_PERIOD": repr(stars.TWINKLE_PERIOD), "TWINKLE_CYCLES_LO": stars.TWINKLE_CYCLES[0],
            "TWINKLE_CYCLES_HI": stars.TWINKLE_CYCLES[1]}


def set_sky_uniforms(program, settings: SkySettings, sun_dir, sun_color, time: float = 0.0,
                     pixel_angle: float = 0.0) -> None:
    """Write every uniform of ``sky/sky.glsl`` (``sun_dir`` is normalised here)."""
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    values = {"sky_sun_dir": tuple(s), "sky_sun_color": tuple(map(float, sun_color)),
              "turbidity": settings.turbidity, "sky_scale": settings.scale,
              "sun_chord": disc_chord(settings.sun_size_deg), "sun_gain": settings.sun_gain,
              "sun_glare": settings.sun_glare,
              "night_color": settings.night,
              "star_threshold": stars.star_threshold(settings.star_density) if settings.stars else 0,
              "star_brightness": settings.star_brightness, "twinkle": settings.twinkle,
              "sky_time": float(time) % stars.TWINKLE_PERIOD, "pixel_angle": float(pixel_angle)}
    write_uniforms(program, values)


def evaluate_sky(gpu, view_dirs, sun_dir, sun_color, settings: SkySettings | None = None, time: float = 0.0,
                 pixel_angle: float = 0.0) -> np.ndarray:
    """(n, 3) float32 sky colours computed on the GPU for ``view_dirs`` (n, 3): what
    :func:`atmos.plugins.sky.radiance.sky_color` computes in float64. ``gpu``: a GpuContext."""
    dirs = unit_vectors(view_dirs, "view_dirs").reshape(-1, 3)
    n = len(dirs)
    if n == 0:
        return np.zeros((0, 3), np.float32)
    prog = gpu.program(compute_shader="sky/eval.comp", defines=sky_defines())
    set_sky_uniforms(prog, settings or SkySettings(), sun_dir, sun_color, time, pixel_angle)
    prog["count"].value = n
    data = np.zeros((n, 4), np.float32)
    data[:, :3] = dirs
    ctx = gpu.ctx
    src = ctx.buffer(data.tobytes())
    out = ctx.buffer(np.full((n, 4), np.nan, np.float32).tobytes())
    try:
        bind_buffers(prog, Directions=src, Colors=out)
        dispatch(prog, math.ceil(n / 64))
        result = np.frombuffer(out.read(), np.float32).reshape(n, 4)
    finally:
        src.release()
        out.release()
    return result[:, :3].copy()     # the output starts as NaN: anything left unwritten shows
