"""Fog post-process after Zdrojewska, "Real time rendering of heterogenous fog" (homogeneous and
Perlin-turbulence heterogeneous fog), as a plugin with one render-graph pass, and :func:`apply_fog`.

Modes: ``linear`` (eq. 2), ``exp`` (eq. 3), ``exp2`` (eq. 4), ``hetero_exp`` (eq. 6) and
``hetero_exp2`` (eq. 7) with the turbulence of eq. (5) from 1-4 octaves of tileable 3D gradient noise
(GPU-made textures or procedural); the blend is eq. (1). See :class:`FogSettings` for every knob.
"""
from __future__ import annotations

import numpy as np

from atmos.checks import check_vec
from atmos.composition import composition
from atmos.gpu.context import release_gl, require_gpu
from atmos.plugin import Plugin
from atmos.plugins.fog.medium import FogMedium
from atmos.plugins.fog.noise import NoiseVolumes
from atmos.plugins.fog.post import FogPass, draw_state, fog_program, restore_state, set_fog_uniforms
from atmos.plugins.fog.settings import MODES, PAPER_RESOLUTIONS, FogSettings
from atmos.plugins.fog.sky_color import SAMPLES, horizon_table, shader_table
from atmos.plugins.sky import SkyLight
from atmos.gpu.uniforms import bind_textures, write_uniforms

__all__ = ["FogMedium", "FogPlugin", "FogSettings", "FogPass", "apply_fog", "MODES", "PAPER_RESOLUTIONS"]


class FogPlugin(Plugin):
    """Adds the ``fog`` pass. ``FogPlugin(settings=None, **fields)`` with :class:`FogSettings`, e.g.
    ``FogPlugin(mode="hetero_exp2", density=0.044)``; ``configure(**changes)`` changes any of them
    live (all or nothing; the pass adapts on the next frame)."""

    settings_class = FogSettings

    def __init__(self, settings: FogSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.fog_pass: FogPass | None = None
        self.medium: FogMedium | None = None   # the fog as other effects see it (published)
        self.composition = self.gpu = None
        self._sky = None
        self._table = None                  # (SceneView, its sky table): held, never a reused id

    def build(self, app) -> None:
        self.gpu = app.gpu
        self.composition = composition(app)
        self.composition.readers.add("fog")       # clouds fogged by their own distance
        self.composition.media_writers.add("fog")  # a local medium the aerial perspective mixes with
        self.composition.media_covers["fog"] = lambda: True     # its dispatch writes every pixel, every frame
        self.medium = FogMedium(self)
        self.fog_pass = FogPass(self)
        app.graph.add_pass(self.fog_pass)
        app.insert_resource(self.medium)

    def finish(self, app) -> None:
        self._sky = app.get_resource(SkyLight)

    def horizon(self, view):
        """This frame's horizon table of ``color_from="sky"`` (:mod:`.sky_color`: the App's sky seen
        from the camera's altitude, at the SceneView ``view``'s sun), None with a fixed colour."""
        if self.settings.color_from != "sky":
            return None
        return horizon_table(view.sun, self._sky, altitude=max(float(view.camera.position[1]), 0.0))

    def sky_table(self, view):
        """:meth:`horizon` by angle from the sun as the shader reads it (:func:`.sky_color.shader_table`),
        None with a fixed colour; made once per frame, whatever the users (the fog pass, the shafts' fog)."""
        if self.settings.color_from != "sky":
            return None
        if self._table is None or self._table[0] is not view:
            self._table = (view, shader_table(self.horizon(view), view.sun))
        return self._table[1]

    def cleanup(self, app) -> None:
        if self.composition is not None:
            self.composition.readers.discard("fog")
            self.composition.media_writers.discard("fog")
            self.composition.media_covers.pop("fog", None)
        if self.fog_pass is not None:
            self.fog_pass.release()


def apply_fog(gpu, color, distance, mode: str = "exp2", density: float = 0.044, fog_color=(0.8, 0.8, 0.8),
              start: float = 0.0, end: float = 100.0, *, positions=None, time: float = 0.0,
              far: float = np.inf, cloud=None, directions=None, camera=(0.0, 0.0, 0.0), horizon=None,
              color_from: str = "fixed", sun=None, **noise) -> np.ndarray:
    """Fog ``color`` (float32 (H, W, 3)) at ``distance`` (float32 (H, W), +inf = sky) on the GPU with
    the pass's shader; returns float32 (H, W, 3).

    Heterogeneous and height modes need ``positions`` (H, W, 3) world positions (finite; height fog:
    each ray's point beyond ``camera``, which gives its slope) and the heterogeneous ones take the noise
    settings of :class:`FogSettings` (``octaves``, ``resolutions``, ``winds``, ``tile_size``,
    ``amplitude``, ``noise``, ``texels_per_cell``, ``seed``) as keywords, plus ``time`` (s);
    ``sky="keep"`` leaves sky pixels alone, else they are fogged at distance ``far``.
    ``cloud`` (H, W, 2): a layer's premultiplied (coverage × distance, coverage) as in
    :mod:`atmos.composition`, fogged by its own distance at ``camera + directions × distance``;
    ``directions`` (H, W, 3) unit view rays (needed with ``cloud`` or ``color_from="sky"``);
    ``horizon`` the (SAMPLES, 3) sky colours of ``color_from="sky"`` (:mod:`.sky_color`); ``sun`` (a
    Sun) the sunlight scattered with ``sun_scattering``.
    ``gpu`` is a GpuContext (the program comes from its cache).
    """
    allowed = [f for f in FogSettings.__dataclass_fields__
               if f not in ("mode", "density", "fog_color", "start", "end", "time_offset", "color_from")]
    unknown = set(noise) - set(allowed)
    if unknown:
        raise ValueError(f"apply_fog got unknown keyword(s) {', '.join(sorted(unknown))}; allowed: "
                         f"{', '.join(allowed)}, positions, time, far")
    settings = FogSettings(mode=mode, density=density, fog_color=fog_color, start=start, end=end,
                           color_from=color_from, **noise)
    color, distance, positions = _check_inputs(color, distance, positions, settings)
    cloud, directions, horizon = _check_layers(distance.shape, cloud, directions, horizon, settings)
    camera = check_vec("apply_fog", "camera", camera, 3)
    far = float(far)
    if np.isnan(far) or far < 0:
        raise ValueError(f"far must be >= 0 or +inf, got {far!r}")
    h, w = distance.shape
    gl = require_gpu(gpu).ctx
    prog = fog_program(gpu, settings, from_depth=False, clouds=cloud is not None)
    made, volumes = [], None
    try:
        target = gl.texture((w, h), 4, np.dstack([color, np.ones((h, w), np.float32)]).tobytes(), dtype="f4")
        made.append(target)
        dist_tex = gl.texture((w, h), 1, distance.tobytes(), dtype="f4")
        made.append(dist_tex)
        pos_tex = gl.texture((w, h), 3, positions.tobytes(), dtype="f4")
        made.append(pos_tex)
        dir_tex = gl.texture((w, h), 3, directions.tobytes(), dtype="f4")
        made.append(dir_tex)
        cloud_tex = gl.texture((w, h), 2, (cloud if cloud is not None else np.zeros((h, w, 2), np.float32)).tobytes(),
                               dtype="f4")
        made.append(cloud_tex)
        for tex in (dist_tex, pos_tex, dir_tex, cloud_tex):
            tex.filter = (gl.NEAREST, gl.NEAREST)
        fbo = gl.framebuffer([target])
        made.append(fbo)
        vao = gl.vertex_array(prog, [])
        made.append(vao)
        if settings.heterogeneous and settings.noise == "texture":
            volumes = NoiseVolumes(gpu, settings)
            volumes.bind(prog)
        bind_textures(prog, fog_distance=dist_tex, fog_position=pos_tex, cloud_distance=cloud_tex, fog_direction=dir_tex)
        set_fog_uniforms(prog, settings, time, None if horizon is None else shader_table(horizon, sun), sun)
        write_uniforms(prog, fog_far=far, fog_camera=tuple(float(v) for v in camera))
        fbo.use()
        gl.viewport = (0, 0, w, h)
        draw_state(gl)
        vao.render(gl.TRIANGLES, vertices=3)
        restore_state(gl)
        out = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(h, w, 4)
        return out[..., :3].copy()
    finally:
        if volumes is not None:
            volumes.release()
        for obj in reversed(made):
            release_gl(obj)


def _check_layers(shape, cloud, directions, horizon, settings):
    """apply_fog's cloud layer, view directions and horizon table, checked and made contiguous."""

    h, w = shape
    needs_dirs = cloud is not None or settings.color_from == "sky" or settings.sun_scattering > 0
    if cloud is not None:
        cloud = np.asarray(cloud)
        if cloud.shape != (h, w, 2) or not np.isfinite(cloud).all():
            raise ValueError(f"cloud must be finite float32 (H, W, 2) = ({h}, {w}, 2) of (coverage × distance, "
                             f"coverage), got shape {cloud.shape}")
        if (cloud < 0).any() or (cloud[..., 1] > 1).any():
            raise ValueError("cloud must hold coverage in [0, 1] and coverage × distance >= 0")
        cloud = np.ascontiguousarray(cloud, np.float32)
    if needs_dirs:
        if directions is None:
            raise ValueError("directions=(H, W, 3) unit view rays are needed with cloud=, color_from='sky' or "
                             "sun_scattering > 0")
        directions = np.asarray(directions)
        if directions.shape != (h, w, 3) or not np.isfinite(directions).all():
            raise ValueError(f"directions must be finite float32 (H, W, 3) = ({h}, {w}, 3), got shape "
                             f"{directions.shape}")
        directions = np.ascontiguousarray(directions, np.float32)
    else:
        directions = np.zeros((h, w, 3), np.float32)
    if settings.color_from == "sky":
        horizon = np.asarray(horizon if horizon is not None else (), np.float64)
        if horizon.shape != (SAMPLES, 3) or not np.isfinite(horizon).all() or (horizon < 0).any():
            raise ValueError(f"horizon must be ({SAMPLES}, 3) non-negative sky colours for color_from='sky' "
                             f"(atmos.plugins.fog.sky_color.horizon_table), got shape {horizon.shape}")
    return cloud, directions, horizon


def _check_inputs(color, distance, positions, settings):
    color = np.asarray(color)
    distance = np.asarray(distance)
    if distance.ndim != 2 or min(distance.shape) < 1:
        raise ValueError(f"distance must be float32 (H, W) with H, W >= 1, got shape {distance.shape}")
    h, w = distance.shape
    if color.shape != (h, w, 3):
        raise ValueError(f"color must be float32 (H, W, 3) = ({h}, {w}, 3) to match distance, got shape {color.shape}")
    color = np.ascontiguousarray(color, np.float32)
    distance = np.ascontiguousarray(distance, np.float32)
    if not np.isfinite(color).all():
        raise ValueError("color must be finite (RGB in [0, 1]); it holds NaN or inf")
    if np.isnan(distance).any() or (distance < 0).any() or np.isneginf(distance).any():
        raise ValueError("distance must be >= 0 metres or +inf (sky); it holds NaN or negative values")
    if settings.heterogeneous or settings.mode == "height":
        if positions is None:
            raise ValueError(f"mode {settings.mode!r} needs positions=(H, W, 3) world positions (for the noise, "
                             f"and for height fog the ray's end: camera + direction × distance)")
        positions = np.asarray(positions)
        if positions.shape != (h, w, 3):
            raise ValueError(f"positions must be float32 (H, W, 3) = ({h}, {w}, 3), got shape {positions.shape}")
        if not np.isfinite(positions).all():
            raise ValueError("positions must be finite world coordinates (use any finite point for sky pixels)")
        positions = np.ascontiguousarray(positions, np.float32)
    else:
        positions = np.zeros((h, w, 3), np.float32)
    return color, distance, positions
