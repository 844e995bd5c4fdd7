"""RegionVolume: the weather ellipsoids rendered into a float 3D texture on the GPU (sec. 4.3.3.3).

The thesis renders every ellipsoid slice into every region-volume slice with MAX blending. Here
two compute passes do the same max over ellipsoids per cell:

1. *scatter* — the CPU computes each ellipsoid's axis-aligned box clipped to the volume (numpy,
   vectorized) and cuts it into chunks of ``CHUNK`` cells; one work group per chunk evaluates
   ``1 − r`` at the cell centres and does ``atomicMax`` on the float bits in a uint buffer
   (non-negative floats order like their bits). Ellipsoids outside the volume (in the region
   margin) cost nothing; work is proportional to the cells the ellipsoids cover.
2. *resolve* — one invocation per cell writes the float value (r32f or r16f) into
   :attr:`RegionVolume.texture`, so every cell is written on every render.

The formulas are those of :mod:`atmos.plugins.clouds.weather.reference`.
"""
from __future__ import annotations

import math

import moderngl
import numpy as np

from atmos.checks import check_shape
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.weather.components import check_ellipsoid_array
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch

CHUNK = 256
_FORMATS = {"f4": ("r32f", "rgba32f", np.float32), "f2": ("r16f", "rgba16f", np.float16)}


class RegionVolume:
    """Region volume of ``shape = (nx, ny, nz)`` cells (y is height) on the GpuContext ``gpu``
    (programs come from its cache); ``dtype`` is ``"f4"`` (r32f, default) or ``"f2"`` (r16f).
    """

    def __init__(self, gpu: GpuContext, shape, dtype: str = "f4"):
        self.gpu, self.ctx = require_gpu(gpu), gpu.ctx
        shape = check_shape(shape)
        if dtype not in _FORMATS:
            raise ValueError(f"dtype must be one of {tuple(_FORMATS)} (r32f or r16f), got {dtype!r}")
        self.shape = shape
        self.dtype = dtype
        cells = math.prod(self.shape)
        limit = int(self.ctx.info.get("GL_MAX_SHADER_STORAGE_BLOCK_SIZE", 2**27))
        max_3d = int(self.ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048))
        if 4 * cells > limit or max(self.shape) > max_3d:
            raise ValueError(f"shape {self.shape} is too big for this GPU (at most {max_3d} cells per axis "
                             f"and {limit // 4} cells in all); use a smaller shape")
        fmt, prob_fmt, self._np_dtype = _FORMATS[dtype]
        self._scatter = self._program("clouds/weather/region_scatter.comp", {"CHUNK": CHUNK})
        self._resolve = self._program("clouds/weather/region_resolve.comp", {"FORMAT": fmt})
        self._probs = self._program("clouds/weather/probabilities.comp", {"FORMAT": prob_fmt})
        self.texture = self.ctx.texture3d(self.shape, 1, dtype=dtype)
        self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.texture.repeat_x = self.texture.repeat_y = self.texture.repeat_z = False
        self.prob_texture = None  # (p_hum, p_act, p_ext, 0) per cell, made by probabilities()
        self._cells = self.ctx.buffer(reserve=4 * cells)
        self._buffers = {}
        self._max_groups = self.ctx.info.get("GL_MAX_COMPUTE_WORK_GROUP_COUNT", (65535, 65535, 65535))
        self.count = 0          # ellipsoids in the last render
        self.work_items = 0     # chunks dispatched in the last render
        self._released = False
        for obj in (self.texture, self._cells):
            gpu.track(obj)

    # -- public --------------------------------------------------------------------------
    def render(self, ellipsoids) -> moderngl.Texture3D:
        """Render an (n, 8) ellipsoid array (columns :data:`.components.COLUMNS`, volume-local cells)
        into :attr:`texture`; every cell is written. Returns the texture."""
        self._check_alive()
        a = check_ellipsoid_array(ellipsoids)
        nx, ny, nz = self.shape
        self.count = len(a)
        self._cells.clear()
        items = self._prepare(a)
        self.work_items = len(items)
        if len(items):
            gx = min(len(items), int(self._max_groups[0]))
            gy = -(-len(items) // gx)
            if gy > int(self._max_groups[1]):
                raise ValueError(f"{len(a)} ellipsoids need {len(items)} work groups, more than this GPU "
                                 f"can dispatch at once; use fewer or smaller ellipsoids")
            write_uniforms(self._scatter, size=self.shape, item_count=len(items), groups_x=gx)
            bind_buffers(self._scatter, Ellipsoids=self._buffers["ellipsoids"], Boxes=self._buffers["boxes"],
                         Items=self._buffers["items"], Region=self._cells)
            dispatch(self._scatter, gx, gy, 1)
        bind_buffers(self._resolve, Region=self._cells)
        bind_images(self._resolve, region=self.texture)
        write_uniforms(self._resolve, size=self.shape)
        dispatch(self._resolve, -(-nx // 8), -(-ny // 8), -(-nz // 4))
        return self.texture

    def download(self) -> np.ndarray:
        """The region volume as float32 (nx, ny, nz), indexed [x, y, z]."""
        self._check_alive()
        nx, ny, nz = self.shape
        data = np.frombuffer(self.texture.read(alignment=1), self._np_dtype)
        return np.ascontiguousarray(data.reshape(nz, ny, nx).transpose(2, 1, 0)).astype(np.float32)

    def probabilities(self, settings=None, *, hum_scale=0.1, act_scale=0.001, ext_scale=0.1,
                      vanish_threshold=0.001) -> moderngl.Texture3D:
        """Fill :attr:`prob_texture` (rgba, same float format) with (p_hum, p_act, p_ext, 0) per cell
        from the current region volume; ``settings`` (a WeatherSettings) overrides the scales."""
        self._check_alive()
        if settings is not None:
            hum_scale, act_scale = settings.hum_scale, settings.act_scale
            ext_scale, vanish_threshold = settings.ext_scale, settings.vanish_threshold
        if self.prob_texture is None:
            self.prob_texture = self.ctx.texture3d(self.shape, 4, dtype=self.dtype)
            self.prob_texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.gpu.track(self.prob_texture)
        nx, ny, nz = self.shape
        bind_textures(self._probs, region=self.texture)
        bind_images(self._probs, probs=self.prob_texture)
        write_uniforms(self._probs, size=self.shape,
                       scales=(hum_scale, act_scale, ext_scale, vanish_threshold))
        dispatch(self._probs, -(-nx // 8), -(-ny // 8), -(-nz // 4))
        return self.prob_texture

    def download_probabilities(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(p_hum, p_act, p_ext) float32 (nx, ny, nz) arrays from :attr:`prob_texture`."""
        self._check_alive()
        if self.prob_texture is None:
            raise RuntimeError("call probabilities() before download_probabilities()")
        nx, ny, nz = self.shape
        data = np.frombuffer(self.prob_texture.read(alignment=1), self._np_dtype).reshape(nz, ny, nx, 4)
        data = data.transpose(2, 1, 0, 3).astype(np.float32)
        return tuple(np.ascontiguousarray(data[..., i]) for i in range(3))

    def release(self) -> None:
        """Release the textures and buffers (the programs belong to the GpuContext)."""
        if self._released:
            return
        self._released = True
        for obj in [self.texture, self._cells, self.prob_texture, *self._buffers.values()]:
            if obj is not None:
                obj.release()
        self._buffers.clear()

    def __repr__(self) -> str:
        return f"RegionVolume(shape={self.shape}, dtype={self.dtype!r}, count={self.count})"

    # -- internals -----------------------------------------------------------------------
    def _program(self, name, defines):
        return self.gpu.program(compute_shader=name, defines=defines)


    def _check_alive(self) -> None:
        if self._released:
            raise RuntimeError("this RegionVolume was released")

    def _upload(self, name: str, data: np.ndarray) -> None:
        raw = data.tobytes()
        buf = self._buffers.get(name)
        if buf is None or buf.size < len(raw):
            if buf is not None:
                buf.release()
            buf = self._buffers[name] = self.ctx.buffer(reserve=max(len(raw), 256) * 2)
            self.gpu.track(buf)
        buf.write(raw)

    def _prepare(self, a: np.ndarray) -> np.ndarray:
        """Upload the ellipsoids, their clipped boxes and the chunk list; return the chunk list."""
        n = len(a)
        if n == 0:
            return np.zeros((0, 2), np.int32)
        c = a[:, 0:3].astype(np.float64)
        yaw = a[:, 3].astype(np.float64)
        r = a[:, 4:7].astype(np.float64)
        valid = (r > 0).all(axis=1)
        r = np.where(r > 0, r, 1.0)
        cs, sn = np.cos(yaw), np.sin(yaw)
        # half extents of the yawed ellipsoid's axis-aligned box, a little generous
        h = np.stack([np.hypot(r[:, 0] * cs, r[:, 2] * sn), r[:, 1], np.hypot(r[:, 0] * sn, r[:, 2] * cs)], axis=1)
        h = h * (1 + 1e-5) + 1e-4
        size = np.array(self.shape, np.float64)
        # cells whose centre i + 0.5 lies in [c - h, c + h], clipped to the volume
        lo = np.clip(np.ceil(c - h - 0.5), 0, size)
        hi = np.clip(np.floor(c + h - 0.5), -1, size - 1)
        ext = (hi - lo + 1).astype(np.int64)
        valid &= (ext > 0).all(axis=1)
        ext = np.where(valid[:, None], ext, 0)
        total = ext.prod(axis=1)
        chunks = -(-total // CHUNK)
        item_count = int(chunks.sum())
        ellipsoids = np.zeros((n, 12), np.float32)
        ellipsoids[:, 0:3] = a[:, 0:3]
        ellipsoids[:, 4:7] = 1.0 / r
        ellipsoids[:, 8] = cs
        ellipsoids[:, 9] = sn
        boxes = np.zeros((n, 8), np.int32)
        boxes[:, 0:3] = lo
        boxes[:, 3] = total
        boxes[:, 4:7] = ext
        if item_count == 0:
            return np.zeros((0, 2), np.int32)
        owner = np.repeat(np.arange(n), chunks)
        first = np.cumsum(chunks) - chunks
        items = np.empty((item_count, 2), np.int32)
        items[:, 0] = owner
        items[:, 1] = (np.arange(item_count) - first[owner]) * CHUNK
        self._upload("ellipsoids", ellipsoids)
        self._upload("boxes", boxes)
        self._upload("items", items)
        return items

