"""The physical sky's look-up tables on the GPU (``shaders/sky/*.comp``; float64 reference:
:mod:`atmos.plugins.sky.atmosphere`).

:class:`AtmosphereLuts` holds the three RGBA32F textures and remakes only what changed:
transmittance and multiple scattering when the :class:`AtmosphereSettings` change, the sky view when
those, the camera's altitude or the sun's height change by more than ``ALTITUDE_TOLERANCE`` /
``SUN_TOLERANCE`` (the sky view is in the sun's frame: the sun's azimuth never changes it). ``builds`` counts the (transmittance, multiple scattering, sky view)
computations, for tests and benchmarks.
"""
from __future__ import annotations

import math
from functools import lru_cache

import moderngl
import numpy as np

import atmos.plugins.sky.atmosphere as ref
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings
from atmos.gpu.uniforms import bind_images, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch

SUN_TOLERANCE = 5e-4          # the sky view is remade when the sun's height (y) moved more (≈ 0.03° near the horizon)
ALTITUDE_TOLERANCE = (1.0, 0.01)   # ... or the camera's altitude by more than max(1 m, 1 %)


SKY_LUTS = "sky_luts"       # the imported AtmosphereLuts of the physical sky (a graph resource)


def camera_altitude(camera) -> float:
    """The camera's height above the ground plane (y = 0), at least 0."""
    return max(float(np.asarray(camera.position, np.float64)[1]), 0.0)


def view_radius(settings: AtmosphereSettings, camera) -> float:
    """The camera's radius from the planet's centre (``view_r`` of the shaders)."""
    return ref.camera_radius(ref.medium(settings), camera_altitude(camera))


@lru_cache(maxsize=1)
def atmosphere_defines() -> dict:
    """The reference's sizes and step counts as defines (one source of truth)."""
    return {"ATM_T_W": ref.TRANSMITTANCE_SIZE[0], "ATM_T_H": ref.TRANSMITTANCE_SIZE[1],
            "ATM_T_STEPS": ref.TRANSMITTANCE_STEPS, "ATM_MS_SIZE": ref.MS_SIZE, "ATM_MS_DIRS": ref.MS_DIRECTIONS,
            "ATM_MS_STEPS": ref.MS_STEPS, "ATM_SV_W": ref.SKY_VIEW_SIZE[0], "ATM_SV_H": ref.SKY_VIEW_SIZE[1],
            "ATM_SV_STEPS": ref.SKY_VIEW_STEPS, "ATM_SUN_EDGE": repr(ref.SUN_EDGE),
            "ATM_RADIUS_EPS": repr(ref.RADIUS_EPS)}


def set_atmosphere_uniforms(program, settings: AtmosphereSettings) -> None:
    """Every uniform of ``sky/atmosphere.glsl`` that ``program`` uses (its LUTs: :meth:`AtmosphereLuts.bind`)."""
    write_uniforms(program, _atmosphere_values(settings))


@lru_cache(maxsize=8)
def _atmosphere_values(settings: AtmosphereSettings) -> dict:
    """The uniform values of :func:`set_atmosphere_uniforms` for ``settings`` (worked out once per settings)."""
    m = ref.medium(settings)
    values = {"atm_rg": m["rg"], "atm_rt": m["rt"], "atm_hr": m["hr"], "atm_hm": m["hm"], "atm_oz_c": m["oz_c"],
              "atm_oz_w": m["oz_w"], "atm_g": m["g"], "atm_ms": m["ms"], "atm_ray": m["ray"], "atm_mie_s": m["mie_s"],
              "atm_mie_t": m["mie_t"], "atm_ozone": m["ozone"], "atm_albedo": m["albedo"], "atm_sun": m["sun"]}
    return {name: tuple(float(x) for x in value) if isinstance(value, np.ndarray) else value
            for name, value in values.items()}


class AtmosphereLuts:
    """The transmittance (256×64, holding the optical depth τ), multiple-scattering (32×32) and sky-view (192×108) textures of one
    sky on ``gpu`` (a GpuContext); :meth:`update` before drawing, :meth:`bind` binds them, :meth:`read`
    returns one as float32 (H, W, 3) (tests), :meth:`release` frees them."""

    def __init__(self, gpu):
        self.gpu = gpu
        sizes = {"transmittance": ref.TRANSMITTANCE_SIZE, "multiscattering": (ref.MS_SIZE, ref.MS_SIZE),
                 "sky_view": ref.SKY_VIEW_SIZE}
        self.textures = {}
        try:
            for name, size in sizes.items():
                tex = gpu.ctx.texture(size, 4, dtype="f4")
                self.textures[name] = tex
                tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
                tex.repeat_x = tex.repeat_y = False
        except BaseException:
            self.release()
            raise
        self._medium_key = None
        self._view_key = None
        self.builds = [0, 0, 0]

    def update(self, settings: AtmosphereSettings, altitude: float, sun_y: float) -> None:
        """Recompute what ``settings``, the camera ``altitude`` (m) and the sun's height ``sun_y``
        (the y of its unit direction) change."""
        if self._medium_key != settings:
            self._run("transmittance", settings)
            self.builds[0] += 1
            self._run("multiscattering", settings)
            self.builds[1] += 1
            self._medium_key, self._view_key = settings, None
        r = ref.camera_radius(ref.medium(settings), altitude)
        sun_y = min(max(float(sun_y), -1.0), 1.0)
        last = self._view_key
        if (last is None or abs(sun_y - last[1]) > SUN_TOLERANCE
                or abs(r - last[0]) > max(ALTITUDE_TOLERANCE[0], ALTITUDE_TOLERANCE[1] * (last[0] - ref.medium(settings)["rg"]))):
            self._run("sky_view", settings, view_r=r, sun_mu=sun_y)
            self.builds[2] += 1
            self._view_key = (r, sun_y)

    @property
    def view_key(self) -> tuple | None:
        """(camera radius, sun height) the sky view was last made for."""
        return self._view_key

    def _run(self, name: str, settings: AtmosphereSettings, **uniforms) -> None:
        program = self.gpu.program(compute_shader=f"sky/{name.replace('_', '')}.comp", defines=atmosphere_defines())
        set_atmosphere_uniforms(program, settings)
        for key, value in uniforms.items():
            program[key].value = value
        if name != "transmittance":
            self.bind(program)
        tex = self.textures[name]
        bind_images(program, lut=tex)
        dispatch(program, math.ceil(tex.width / 8), math.ceil(tex.height / 8))

    def bind(self, program) -> None:
        """Bind the textures ``program`` samples (``atm_transmittance``, ``atm_multiscattering``, ``sky_view``)."""
        bind_textures(program, atm_transmittance=self.textures["transmittance"],
                      atm_multiscattering=self.textures["multiscattering"], sky_view=self.textures["sky_view"])

    def read(self, name: str) -> np.ndarray:
        """float32 (height, width, 3) of the texture ``name`` ("transmittance", "multiscattering", "sky_view")."""
        tex = self.textures[name]
        return np.frombuffer(tex.read(), np.float32).reshape(tex.height, tex.width, 4)[..., :3].copy()

    def release(self) -> None:
        for tex in self.textures.values():
            tex.release()
        self.textures = {}
