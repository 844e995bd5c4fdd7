"""PassContext: what a pass's ``execute`` sees — its textures, cached framebuffers, a fullscreen draw."""
from __future__ import annotations

from collections import OrderedDict

import moderngl

from atmos.gpu.context import release_gl
from atmos.graph.errors import GraphError

FRAMEBUFFER_CACHE = 64  # framebuffers kept per graph, least recently used dropped first


class PassContext:
    """Handed to :meth:`RenderPass.execute`; one object per graph, reused every frame.

    ``gpu`` is the GpuContext, ``data`` the keyword arguments of ``RenderGraph.execute`` and
    ``pass_name`` the pass now running. Framebuffers and the fullscreen VAO are cached, so a
    steady frame allocates no GL objects.
    """

    def __init__(self, gpu):
        self.gpu = gpu
        self.data: dict = {}
        self.pass_name = ""
        self._textures: dict[str, object] = {}   # this frame's resolved resources
        self._declared: frozenset[str] = frozenset()
        self._framebuffers: OrderedDict = OrderedDict()
        self._vaos: dict[int, tuple[object, object]] = {}

    def texture(self, name: str):
        """The texture behind ``name`` this frame: a pooled transient or the resolved import.

        An imported framebuffer is returned as that framebuffer.
        """
        if name not in self._declared:
            raise GraphError(f"pass '{self.pass_name}' uses '{name}' but did not declare it in setup() "
                             "(declare it with builder.create/read/write)")
        try:
            return self._textures[name]
        except KeyError:
            raise GraphError(f"pass '{self.pass_name}': resource '{name}' is not available this frame") from None

    def framebuffer(self, color=(), depth: str | None = None):
        """A framebuffer over the named textures, cached by texture identity.

        ``color`` is a name or a list of names. An imported framebuffer (such as the screen target)
        named alone as ``color`` is returned as it is.
        """
        names = [color] if isinstance(color, str) else list(color)
        attachments = [self.texture(n) for n in names]
        depth_attachment = self.texture(depth) if depth is not None else None
        if any(isinstance(a, moderngl.Framebuffer) for a in attachments + [depth_attachment]):
            if len(attachments) == 1 and depth_attachment is None:
                return attachments[0]
            raise GraphError(f"pass '{self.pass_name}': the imported framebuffer among {names + [depth]} "
                             "can only be used alone as framebuffer(color=[name])")
        if not attachments and depth_attachment is None:
            raise GraphError(f"pass '{self.pass_name}': framebuffer() needs at least one color or a depth name")
        key = tuple(id(a) for a in attachments) + (id(depth_attachment),)
        entry = self._framebuffers.get(key)
        if entry is not None and all(_alive(a) for a in entry[1]):
            self._framebuffers.move_to_end(key)
            return entry[0]
        if entry is not None:
            self._drop(key)
        fbo = self.gpu.ctx.framebuffer(attachments, depth_attachment)
        # the cache holds the attachments too, so an id() in the key cannot be reused while cached
        self._framebuffers[key] = (fbo, attachments + ([depth_attachment] if depth_attachment else []))
        while len(self._framebuffers) > FRAMEBUFFER_CACHE:
            self._drop(next(iter(self._framebuffers)))
        return fbo

    def fullscreen(self, program) -> None:
        """Draw the fullscreen triangle (``lib/fullscreen.vert``) with ``program`` into the bound framebuffer."""
        entry = self._vaos.get(id(program))
        if entry is None or entry[1] is not program:
            entry = self._vaos[id(program)] = (self.gpu.ctx.vertex_array(program, []), program)
        entry[0].render(moderngl.TRIANGLES, vertices=3)

    def _drop(self, key) -> None:
        fbo, _ = self._framebuffers.pop(key)
        release_gl(fbo)

    def _begin_frame(self, data: dict, textures: dict) -> None:
        self.data = data
        self._textures = textures

    def _begin_pass(self, name: str, declared: frozenset[str]) -> None:
        self.pass_name = name
        self._declared = declared
        ctx = self.gpu.ctx                # every pass starts from the same GL state
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        ctx.blend_func = moderngl.DEFAULT_BLENDING
        ctx.blend_equation = moderngl.FUNC_ADD

    def blend_transmittance(self) -> None:
        """Blend a participating medium's (in-scattered light, transmittance T) over the colour:
        rgb = light + T · rgb, alpha kept: the medium does not occlude the sky (``color.a``, see
        :mod:`atmos.render_core`). What the fog passes output."""
        ctx = self.gpu.ctx
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.ONE, moderngl.SRC_ALPHA, moderngl.ZERO, moderngl.ONE

    def blend_over(self) -> None:
        """Blend a premultiplied layer (light, coverage a = 1 − T) over the colour, (ONE, ONE_MINUS_SRC_ALPHA)
        on colour and alpha: rgb = light + (1 − a) · rgb and alpha = a + (1 − a) · alpha, so the layer
        adds its coverage to the sky occlusion in ``color.a`` (see :mod:`atmos.render_core`). What
        clouds and cloud layers output."""
        ctx = self.gpu.ctx
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = (moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)

    def _end_frame(self) -> None:
        self.pass_name = ""
        self._declared = frozenset()
        self._textures = {}

    def release(self) -> None:
        """Release the cached framebuffers and vertex arrays."""
        for key in list(self._framebuffers):
            self._drop(key)
        for vao, _ in self._vaos.values():
            vao.release()
        self._vaos.clear()


def _alive(obj) -> bool:
    """False once a moderngl object has been released."""
    return not isinstance(getattr(obj, "mglo", None), moderngl.InvalidObject)
