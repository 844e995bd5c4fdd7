"""PassContext: what a pass's ``execute`` sees — the scene view, its resources, cached framebuffers,
a fullscreen draw — and the one place that resets GL state before every pass."""
from __future__ import annotations

from collections import OrderedDict

import moderngl

from atmos.gpu.context import GpuError, release_gl
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures
from atmos.graph.errors import GraphError

_PLAIN = frozenset((moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube,
                    moderngl.Buffer))
_FRAMEBUFFER_TYPES: dict[type, bool] = {}   # type of an imported resource -> whether it is a Framebuffer
FRAMEBUFFER_CACHE = 64  # framebuffers kept per graph, least recently used dropped first
STATE_FLAGS = moderngl.BLEND | moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.PROGRAM_POINT_SIZE
_DEFAULT_BLEND_FUNC = tuple(moderngl.DEFAULT_BLENDING)   # reset_state's values, as moderngl's setters pass them
_DEFAULT_BLEND_EQUATION = (moderngl.FUNC_ADD,)

# The blend modes passes use (colour factors, then alpha factors); see the PassContext methods.
BLEND_OVER = (moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)
BLEND_TRANSMITTANCE = (moderngl.ONE, moderngl.SRC_ALPHA, moderngl.ZERO, moderngl.ONE)
BLEND_ALPHA = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ZERO, moderngl.ONE)


def blend(ctx, factors) -> None:
    """Enable blending with ``factors`` (one of the BLEND_* modes); also for draws outside a graph."""
    ctx.enable(moderngl.BLEND)
    ctx.blend_func = factors


class PassContext:
    """Handed to :meth:`RenderPass.execute`; one object per graph, reused every frame.

    ``view`` is this frame's :class:`atmos.SceneView` (camera, sun, clock, size), ``gpu`` the
    GpuContext and ``pass_name`` the pass now running. Every pass starts from the same GL state
    (:meth:`reset_state`): no blending, no depth test (depth function ``<``), no culling, no
    program point size, and each framebuffer it takes starts with depth and colour writes on, the
    full viewport and no scissor — so no pass restores state by hand. Framebuffers and the fullscreen VAO are cached,
    so a steady frame allocates no GL objects.
    """

    def __init__(self, gpu):
        self.gpu = gpu
        self.view = None
        self.pass_name = ""
        self._resources: dict[str, object] = {}   # this frame's resolved resources
        self._declared: frozenset[str] = frozenset()
        self._access: dict[str, tuple] = {}       # the running pass's (read, write) access by name
        self._framebuffers: OrderedDict = OrderedDict()
        self._vaos: dict[int, tuple[object, object]] = {}
        self._fresh: set[int] = set()             # framebuffers already reset in this pass

    def declares(self, name: str) -> bool:
        """Whether the running pass declared ``name`` this frame (for a declaration made only sometimes)."""
        return name in self._declared

    def resource(self, name: str):
        """The resource behind ``name`` this frame: a pooled transient texture or the resolved import
        (a texture, a framebuffer such as the screen, or any imported object)."""
        if name not in self._declared:
            raise GraphError(f"pass '{self.pass_name}' uses '{name}' but did not declare it in setup() "
                             "(declare it with builder.create/read/write)")
        try:
            value = self._resources[name]
        except KeyError:
            raise GraphError(f"pass '{self.pass_name}': resource '{name}' is not available this frame") from None
        kind = type(value)
        if kind in _PLAIN:                  # a texture or buffer: no framebuffer to reset
            return value
        try:
            framebuffer = _FRAMEBUFFER_TYPES[kind]
        except KeyError:
            framebuffer = _FRAMEBUFFER_TYPES[kind] = issubclass(kind, moderngl.Framebuffer)
        if framebuffer:
            self._reset_framebuffer(value)
        return value

    def framebuffer(self, color=(), depth: str | None = None):
        """A framebuffer over the named textures, cached by texture identity.

        ``color`` is a name or a list of names. An imported framebuffer (such as the screen target)
        named alone as ``color`` is returned as it is.
        """
        names = [color] if type(color) is str else list(color)
        declared, resources = self._declared, self._resources
        attachments, slow = [], False       # the common case: declared textures, known this frame
        for n in names:
            if n in declared and n in resources:
                a = resources[n]
                attachments += (a,)
                if type(a) is moderngl.Framebuffer:
                    slow = True
            else:
                slow = True
        depth_attachment = None
        if depth is not None:
            if depth in declared and depth in resources:
                depth_attachment = resources[depth]
            else:
                slow = True
        if slow or type(depth_attachment) is moderngl.Framebuffer:
            attachments = [self.resource(n) for n in names]          # the errors, and imported framebuffers
            depth_attachment = self.resource(depth) if depth is not None else None
            slow = any(isinstance(a, moderngl.Framebuffer) for a in attachments + [depth_attachment])
        if slow:
            if len(attachments) == 1 and depth_attachment is None:
                return attachments[0]
            raise GraphError(f"pass '{self.pass_name}': the imported framebuffer among {names + [depth]} "
                             "can only be used alone as framebuffer(color=[name])")
        if not attachments and depth_attachment is None:
            raise GraphError(f"pass '{self.pass_name}': framebuffer() needs at least one color or a depth name")
        hazards = self.gpu.hazards
        dirty = hazards._dirty      # a texture a compute pass wrote, now drawn into: its writes first
        if dirty and not dirty.keys().isdisjoint(map(id, attachments + [depth_attachment])):
            hazards.use(reads=[(a, "attachment") for a in attachments + [depth_attachment] if a is not None])
        key = (*map(id, attachments), id(depth_attachment))
        entry = self._framebuffers.get(key)
        if entry is not None:
            for a in entry[1]:
                if type(a.mglo) is moderngl.InvalidObject:     # _alive, inlined: released since
                    break
            else:
                self._framebuffers.move_to_end(key)
                return self._reset_framebuffer(entry[0])
        if entry is not None:
            self._drop(key)
        try:
            fbo = self.gpu.ctx.framebuffer(attachments, depth_attachment)
        except moderngl.Error as error:
            size = "x".join(map(str, (attachments or [depth_attachment])[0].size))
            raise GpuError(f"pass '{self.pass_name}': the GPU could not make a {size} framebuffer of "
                           f"{names + ([depth] if depth else [])} ({error}): most likely out of GPU memory at this "
                           f"frame size; try a smaller one") from None
        # the cache holds the attachments too, so an id() in the key cannot be reused while cached
        self._framebuffers[key] = (fbo, attachments + ([depth_attachment] if depth_attachment else []))
        while len(self._framebuffers) > FRAMEBUFFER_CACHE:
            self._drop(next(iter(self._framebuffers)))
        self._fresh.add(id(fbo))
        return fbo

    def image(self, name: str):
        """The texture ``name`` for image load/store: the pass must have declared it with ``storage`` access."""
        access = self._access
        if name in self._declared and name in access and "storage" in access[name]:   # a texture: no checks left
            value = self._resources.get(name)
            if type(value) in _PLAIN:
                return value
        value = self.resource(name)
        if name not in access or "storage" not in access[name]:
            raise GraphError(f"pass '{self.pass_name}' uses '{name}' as an image but declared it without "
                             "access='storage' (builder.read/write(name, access='storage'))")
        return value

    def dispatch(self, program, groups, textures=None, images=None, buffers=None) -> None:
        """Bind by name and run compute ``program`` over ``groups`` (x[, y[, z]]) work groups.

        ``textures`` (sampler name -> resource name or texture), ``images`` (image name -> resource
        name, declared with storage access, or texture) and ``buffers`` (storage block name -> resource
        name or buffer); the binds get the barriers their uses need (:mod:`atmos.gpu.hazards`)."""
        if textures:
            bind_textures(program, self._named(textures))
        if images:
            bind_images(program, self._named(images, True))
        if buffers:
            bind_buffers(program, self._named(buffers))
        dispatch(program, *groups)

    def _named(self, binds: dict, image: bool = False) -> dict:
        """``binds`` with each resource name replaced by this frame's resource (checked as
        :meth:`resource`, or :meth:`image` for ``image`` binds); objects kept as they are."""
        declared, resources, access = self._declared, self._resources, self._access
        out = {}
        for k in binds:
            v = binds[k]
            if type(v) is str:
                if (v in declared and v in resources and type(resources[v]) is not moderngl.Framebuffer
                        and (not image or v in access and "storage" in access[v])):
                    v = resources[v]
                else:
                    v = self.image(v) if image else self.resource(v)    # the errors (and framebuffers)
            out[k] = v
        return out

    def fullscreen(self, program) -> None:
        """Draw the fullscreen triangle (``lib/fullscreen.vert``) with ``program`` into the bound framebuffer."""
        entry = self._vaos.get(id(program))
        if entry is None or entry[1] is not program:
            entry = self._vaos[id(program)] = (self.gpu.ctx.vertex_array(program, []), program)
        entry[0].render(moderngl.TRIANGLES, vertices=3)

    def blend_transmittance(self) -> None:
        """Blend a participating medium's (in-scattered light, transmittance T) over the colour:
        rgb = light + T · rgb, alpha kept: the medium does not occlude the sky (``color.a``, see
        :mod:`atmos.render_core`). What the fog passes output."""
        blend(self.gpu.ctx, BLEND_TRANSMITTANCE)

    def blend_over(self) -> None:
        """Blend a premultiplied layer (light, coverage a = 1 − T) over the colour, (ONE, ONE_MINUS_SRC_ALPHA)
        on colour and alpha: rgb = light + (1 − a) · rgb and alpha = a + (1 − a) · alpha, so the layer
        adds its coverage to the sky occlusion in ``color.a`` (see :mod:`atmos.render_core`). What
        clouds and cloud layers output."""
        blend(self.gpu.ctx, BLEND_OVER)

    def blend_alpha(self) -> None:
        """Blend straight-alpha colour (rgb, a) over the target, its alpha kept: what HUD layers (text,
        frame-time bars) draw onto the presented screen, whose alpha stays 1."""
        blend(self.gpu.ctx, BLEND_ALPHA)

    def reset_state(self) -> None:
        """The GL state every pass starts from (and a frame ends with): set on the context's C object
        (``mglo``) as moderngl's own setters do, without their Python wrappers (once per pass)."""
        gl = self.gpu.ctx.mglo
        gl.disable(STATE_FLAGS)
        gl.blend_func = _DEFAULT_BLEND_FUNC
        gl.blend_equation = _DEFAULT_BLEND_EQUATION
        gl.depth_func = "<"
        self._fresh = set()

    def _reset_framebuffer(self, fbo):
        """Depth and colour writes on, the full viewport, no scissor: the first time a pass takes ``fbo``
        (set on its C object, ``mglo``, as moderngl's setters do)."""
        key = id(fbo)
        if key not in self._fresh:
            self._fresh.add(key)
            gl = fbo.mglo
            gl.depth_mask = True
            n = len(fbo.color_attachments or ())   # a window's default framebuffer has none listed
            if n:                            # moderngl takes one mask, or one per attachment
                gl.color_mask = (True, True, True, True) if n == 1 else ((True, True, True, True),) * n
            w, h = fbo.size
            gl.viewport = (0, 0, int(w), int(h))
            gl.scissor = None
        return fbo

    def _drop(self, key) -> None:
        fbo, _ = self._framebuffers.pop(key)
        self._fresh.discard(id(fbo))
        release_gl(fbo)

    def _end_frame(self) -> None:
        """The frame ends as every pass starts, with the host's framebuffer (``gpu.target``: a window's
        screen) bound at its full size, so a host that draws next draws where it expects."""
        self.reset_state()
        target = self.gpu.target
        target.scissor = None
        target.viewport = (0, 0, *target.size)
        target.use()
        self.pass_name = ""
        self._declared = frozenset()
        self._resources = {}

    def drop_released(self) -> int:
        """Release cached framebuffers over textures that were released (evicted by the pool): a GL
        framebuffer keeps a deleted texture's storage alive. Returns how many were dropped."""
        dead = [key for key, (_, attachments) in self._framebuffers.items()
                if not all(_alive(a) for a in attachments)]
        for key in dead:
            self._drop(key)
        return len(dead)

    @property
    def cached_framebuffers(self) -> int:
        """Framebuffers held by the cache now (tests count GL objects with it)."""
        return len(self._framebuffers)

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
