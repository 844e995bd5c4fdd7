"""The sky shader's defines and uniforms, shared by the sky pass and a compute evaluation of it."""
from __future__ import annotations

import math

import numpy as np

from atmos.camera import gl_matrix3, view_basis
from atmos.plugins.sky import stars
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.preetham import COS_FLOOR, unit_vectors

DAY_FADE = (-0.2, 0.02)      # sun height (sin elevation): night below the first, full Preetham day above the second
GROUND_DIM = 0.3
BELOW_FADE = 0.1
DISC_EDGE = 0.25


def disc_chords(size_deg: float) -> tuple[float, float]:
    """Chord lengths |v − s| where the disc's soft edge starts and ends."""
    r = math.radians(size_deg)
    return 2.0 * math.sin(0.5 * r * (1.0 - DISC_EDGE)), 2.0 * math.sin(0.5 * r)


def sky_defines() -> dict:
    """The constants of the float64 reference, handed to the GLSL as defines (one source of truth)."""
    return {"SKY_COS_FLOOR": repr(COS_FLOOR), "DAY_LO": repr(DAY_FADE[0]), "DAY_HI": repr(DAY_FADE[1]),
            "GROUND_DIM": repr(GROUND_DIM), "BELOW_FADE": repr(BELOW_FADE),
            "STAR_GRID": stars.STAR_GRID, "STAR_KEY_A": f"{stars.STAR_KEY[0]}u", "STAR_KEY_B": f"{stars.STAR_KEY[1]}u",
            "STAR_SIGMA": repr(stars.STAR_SIGMA), "STAR_SIGMA_MAX": repr(stars.STAR_SIGMA_MAX),
            "STAR_CUT_LO": repr(stars.STAR_CUT[0]), "STAR_CUT_HI": repr(stars.STAR_CUT[1]),
            "STAR_NIGHT_LO": repr(stars.STAR_NIGHT[0]), "STAR_NIGHT_HI": repr(stars.STAR_NIGHT[1]),
            "STAR_HORIZON": repr(stars.STAR_HORIZON),
            "TWINKLE_PERIOD": repr(stars.TWINKLE_PERIOD), "TWINKLE_CYCLES_LO": stars.TWINKLE_CYCLES[0],
            "TWINKLE_CYCLES_HI": stars.TWINKLE_CYCLES[1]}


def set_view_basis(program, camera, aspect: float) -> None:
    """Write the ``view_basis`` uniform of ``sky/sky.frag`` (:func:`atmos.camera.view_basis`)."""
    program["view_basis"].write(gl_matrix3(view_basis(camera, aspect)))


def set_sky_uniforms(program, settings: SkySettings, sun_dir, sun_color, time: float = 0.0,
                     pixel_angle: float = 0.0) -> None:
    """Write every uniform of ``sky/sky.glsl`` (``sun_dir`` is normalised here)."""
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    values = {"sky_sun_dir": tuple(s), "sky_sun_color": tuple(float(c) for c in sun_color),
              "turbidity": settings.turbidity, "sky_scale": settings.scale,
              "sun_chords": disc_chords(settings.sun_size_deg), "sun_gain": settings.sun_gain,
              "night_color": settings.night,
              "star_threshold": stars.star_threshold(settings.star_density) if settings.stars else 0,
              "star_brightness": settings.star_brightness, "twinkle": settings.twinkle,
              "sky_time": float(time) % stars.TWINKLE_PERIOD, "pixel_angle": float(pixel_angle)}
    for name, value in values.items():
        if name in program:
            program[name].value = value


def evaluate_sky(gpu, view_dirs, sun_dir, sun_color, settings: SkySettings | None = None, time: float = 0.0,
                 pixel_angle: float = 0.0) -> np.ndarray:
    """(n, 3) float32 sky colours computed on the GPU for ``view_dirs`` (n, 3): what
    :func:`atmos.plugins.sky.reference.sky_color` computes in float64. ``gpu``: a GpuContext."""
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
        src.bind_to_storage_buffer(0)
        out.bind_to_storage_buffer(1)
        prog.run(math.ceil(n / 64))
        ctx.memory_barrier()
        result = np.frombuffer(out.read(), np.float32).reshape(n, 4)
    finally:
        src.release()
        out.release()
    return result[:, :3].copy()     # the output starts as NaN: anything left unwritten shows
