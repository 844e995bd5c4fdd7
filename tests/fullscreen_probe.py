"""Run one fullscreen fragment shader on its own: a test helper for shader-level comparisons with numpy."""
from __future__ import annotations

import moderngl
import numpy as np

from atmos.gpu.context import release_gl
from atmos.gpu.uniforms import bind_textures

DTYPES = {np.dtype(np.float16): "f2", np.dtype(np.float32): "f4"}


def run_fullscreen(gpu, fragment: str, size, inputs=None, set_uniforms=None, defines=None,
                   nearest: bool = False) -> np.ndarray:
    """(h, w, 4) float64 output of ``lib/fullscreen.vert`` + ``fragment`` drawn once into a
    NaN-prefilled RGBA32F target, so an unwritten pixel shows. ``inputs``: {sampler name: float16/float32
    array (h, w) or (h, w, c)}, each bound as a texture to that sampler (``nearest``: no filtering);
    ``set_uniforms(program)`` runs before the draw. Everything made here is released."""
    ctx = gpu.ctx
    w, h = size
    program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader=fragment, defines=defines)
    textures = {}
    for name, array in (inputs or {}).items():
        array = np.ascontiguousarray(array)
        tex = ctx.texture(array.shape[1::-1], 1 if array.ndim == 2 else array.shape[2], array.tobytes(),
                          dtype=DTYPES[array.dtype])
        if nearest:
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        textures[name] = tex
    dst = ctx.texture((w, h), 4, np.full((h, w, 4), np.nan, np.float32).tobytes(), dtype="f4")
    fbo = ctx.framebuffer([dst])
    vao = ctx.vertex_array(program, [])
    try:
        fbo.use()
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST)
        bind_textures(program, textures)
        if set_uniforms is not None:
            set_uniforms(program)
        vao.render(moderngl.TRIANGLES, vertices=3)
        return np.frombuffer(dst.read(), np.float32).reshape(h, w, 4).astype(np.float64)
    finally:
        gpu.target.use()
        vao.release()
        release_gl(fbo)
        for obj in (dst, *textures.values()):
            obj.release()
