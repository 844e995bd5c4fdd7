"""One GPU context type for a pyglet window and for headless EGL rendering into an offscreen framebuffer."""
from __future__ import annotations

import operator
import sys
import weakref

import moderngl
import numpy as np

from atmos.gpu.host_memory import is_software, return_freed_textures
from atmos.gpu.hazards import Hazards, hazards_of
from atmos.gpu.queries import QueryPool, query_pool
from atmos.gpu.portability import check_enabled, check_program
from atmos.gpu.shaders import ShaderError, compile_program, load_stages

MIN_GL_VERSION = 430  # compute shaders


class GpuError(RuntimeError):
    """No usable OpenGL, or one older than atmos needs; the message says which and what to do."""


def _check_version(ctx: moderngl.Context) -> None:
    if ctx.version_code < MIN_GL_VERSION:
        raise GpuError(
            f"atmos needs OpenGL 4.3 or newer (compute shaders); this context is OpenGL "
            f"{ctx.info.get('GL_VERSION', ctx.version_code)} on {ctx.info.get('GL_RENDERER', 'an unknown renderer')}. "
            "Update the graphics driver, or use Mesa's llvmpipe (LIBGL_ALWAYS_SOFTWARE=1).")


def release_gl(obj) -> None:
    """Release a moderngl object; a framebuffer is never left bound.

    moderngl re-binds the last bound framebuffer after it makes a new one, and binding a released
    one is GL_INVALID_OPERATION; so a bound framebuffer is swapped for framebuffer 0 first.
    """
    if isinstance(obj, moderngl.Framebuffer):
        ctx = obj.ctx
        if ctx.fbo is not None and ctx.fbo.glo == obj.glo:
            ctx.detect_framebuffer(0).use()
    obj.release()


def check_frame_size(size, limit: int | None = None, what: str = "size") -> tuple[int, int]:
    """``(width, height)`` as ints: two whole numbers >= 0 (0, a minimized window, becomes 1) and at
    most ``limit`` (the context's largest render target); a ValueError naming ``what`` otherwise."""
    try:
        values = None if isinstance(size, (str, bytes)) else tuple(size)
        w, h = (None if isinstance(v, (bool, np.bool_)) else operator.index(v) for v in values)
    except (TypeError, ValueError):
        w = h = None
    if w is None or h is None or min(w, h) < 0 or (limit is not None and max(w, h) > limit):
        top = f"0..{limit}" if limit is not None else ">= 0"
        raise ValueError(f"{what} must be (width, height), two whole numbers {top} (0: a minimized window), "
                         f"got {size!r}")
    return max(1, int(w)), max(1, int(h))


def window_framebuffer(ctx: moderngl.Context, size: tuple[int, int]) -> moderngl.Framebuffer:
    """The window's framebuffer (GL name 0) at its current ``size``. moderngl keeps the size the window
    had when the context was made (``ctx.screen.size``), and the render graph sets each pass's viewport
    from a framebuffer's size, so after a resize frames would fill only the old rectangle."""
    screen = ctx.detect_framebuffer(0)
    screen._size = tuple(size)               # moderngl has no public setter for it
    screen.viewport = (0, 0, *size)
    return screen


def clamp_sampler(ctx: moderngl.Context):
    """Linear, clamp-to-edge: a texture's outer half texels hold the edge value, never wrap around."""
    return ctx.sampler(filter=(moderngl.LINEAR, moderngl.LINEAR), repeat_x=False, repeat_y=False, repeat_z=False)


def create_headless(size: tuple[int, int] = (640, 360), backend: str = "egl") -> "GpuContext":
    """A standalone context (EGL by default) that renders into an offscreen framebuffer of ``size``."""
    check_frame_size(size)
    if not isinstance(backend, str) or not backend:
        raise ValueError(f"backend must be a glcontext backend name such as 'egl', got {backend!r}")
    try:
        # asked for explicitly: NVIDIA's EGL hands out OpenGL 3.3 unless 4.3 is requested (Mesa gives its newest)
        ctx = moderngl.create_standalone_context(require=MIN_GL_VERSION, backend=backend)
    except Exception as error:  # moderngl/glcontext raise plain Exceptions with the loader's message
        raise GpuError(
            f"no usable OpenGL: creating a headless {backend.upper()} OpenGL 4.3 core context failed ({error}). "
            "Install Mesa's EGL and DRI drivers (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri) "
            "or a GPU driver with EGL.") from None
    try:
        _check_version(ctx)
        return GpuContext(ctx, size, headless=True)
    except Exception:
        ctx.release()
        raise


def from_current(size: tuple[int, int]) -> "GpuContext":
    """Wrap the OpenGL context current in this thread (a pyglet or Arcade window's); draws go to its screen."""
    try:
        ctx = moderngl.create_context()
    except Exception as error:
        raise GpuError(f"no usable OpenGL in the window: {error}") from None
    return wrap_context(ctx, size)


def wrap_context(ctx, size: tuple[int, int]) -> "GpuContext":
    """atmos on a moderngl context the host owns (a moderngl-window ``WindowConfig``'s ``self.ctx``):
    frames go to its window framebuffer (GL name 0) at ``size``, the framebuffer's size in pixels;
    after a resize call ``gpu.resize(new_size)``. ``gpu.release()`` leaves the context to the host."""
    if not isinstance(ctx, moderngl.Context):
        raise ValueError(f"wrap_context needs a moderngl.Context (a window's, e.g. WindowConfig.ctx), got {ctx!r}; "
                         "for the context current in this thread use atmos.from_current(size)")
    _check_version(ctx)
    return GpuContext(ctx, size, headless=False)


_NOTICED: list = []   # one notice per process


def _notice_software_window(ctx) -> None:
    """Print once per process, to stderr, that a window renders on a software rasterizer."""
    if _NOTICED:
        return
    _NOTICED.append(ctx.info.get("GL_RENDERER", "?"))
    print(f"atmos: this window's OpenGL is a software rasterizer ({_NOTICED[0]}): the frames are right, but "
          "frame times will be slow; a GPU driver with OpenGL 4.3 makes them real time", file=sys.stderr, flush=True)


def require_gpu(gpu, what: str = "gpu") -> "GpuContext":
    """``gpu`` itself when it is a :class:`GpuContext`; a ValueError naming ``what`` otherwise (the
    libraries take the GpuContext, never a bare moderngl context, so every program comes from
    :meth:`GpuContext.program`)."""
    if not isinstance(gpu, GpuContext):
        raise ValueError(f"{what} must be an atmos GpuContext (atmos.gpu.create_headless or from_current), "
                         f"got {type(gpu).__name__}")
    return gpu


class GpuContext:
    """A moderngl context, the framebuffer frames are drawn into, and a cache of compiled programs.

    Everything made through :meth:`track` or :meth:`program` is released by :meth:`release`; after
    it, using the context is a :class:`GpuError` (a second ``release`` does nothing).
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], headless: bool):
        self.ctx = ctx
        self.headless = headless
        self.size = (0, 0)
        self._programs: dict[tuple, object] = {}
        self._fast_programs: dict[tuple, object] = {}   # the same programs by their arguments' order as given
        self._tracked: "weakref.WeakSet" = weakref.WeakSet()
        self._offscreen: list = []
        self.released = False
        self._apps: "weakref.WeakSet" = weakref.WeakSet()   # open Apps on this context (closed first by release)
        self.queries: QueryPool = query_pool(ctx)  # query objects shared by every App on this context
        self.hazards: Hazards = hazards_of(ctx)    # storage writes not yet visible: barriers come from it
        self.software = is_software(ctx)
        if self.software:
            return_freed_textures()
            if not headless:
                _notice_software_window(ctx)
        self.target: moderngl.Framebuffer = ctx.screen
        self.resize(size)

    def make_current(self) -> None:
        """Make this the thread's current OpenGL context. moderngl does not switch contexts by
        itself: with two contexts in one process (two headless Apps, a tool beside a game), GL
        calls go to whichever was made current last. App.update and the methods here call it."""
        self._require_live()
        self.ctx.__enter__()

    def _require_live(self) -> None:
        if self.released:
            raise GpuError("this GpuContext was released (GpuContext.release); create a new one "
                           "(atmos.create_headless or atmos.from_current)")

    @property
    def max_size(self) -> int:
        """The largest frame width or height this context can render (its texture, renderbuffer and
        viewport limits)."""
        info = self.ctx.info
        viewport = info.get("GL_MAX_VIEWPORT_DIMS", (16384, 16384))
        return int(min(info.get("GL_MAX_TEXTURE_SIZE", 16384), info.get("GL_MAX_RENDERBUFFER_SIZE", 16384),
                       *viewport))

    # -- framebuffer -----------------------------------------------------------------------
    def resize(self, size: tuple[int, int]) -> None:
        """Set the frame size; a minimized window (0 in either axis) keeps a 1×1 target. A size the
        context cannot render (above :attr:`max_size`, negative, not whole numbers) is a ValueError."""
        self._require_live()
        size = check_frame_size(size, self.max_size, "GpuContext size")
        if size == self.size:
            return
        self.make_current()
        if self.headless:                 # the new target first: if the GPU cannot make it, the old one stays
            made = []
            try:
                made.append(self.ctx.texture(size, 4))
                made.append(self.ctx.depth_renderbuffer(size))
                made.insert(0, self.ctx.framebuffer([made[0]], made[1]))
            except moderngl.Error as error:
                for obj in made:
                    release_gl(obj)
                raise GpuError(f"the GPU could not make a {size[0]}x{size[1]} frame ({error}): most likely out of "
                               f"GPU memory; try a smaller size (this context allows up to {self.max_size} a side)") from None
            for obj in self._offscreen:
                release_gl(obj)
            self.size = size
            self.target, self._offscreen = made[0], made
        else:
            self.size = size
            for obj in self._offscreen:          # the read_pixels copy of the old size
                release_gl(obj)
            self._offscreen = []
            self.target = window_framebuffer(self.ctx, size)

    def read_pixels(self) -> np.ndarray:
        """The current frame as uint8 RGB, shape (height, width, 3), first row at the top. In a window
        the frame is copied to a texture first (moderngl's read of a window's framebuffer selects a
        colour attachment it does not have: GL_INVALID_OPERATION), so no GL error is left behind."""
        self.make_current()
        w, h = self.size
        source = self.target
        if not self.headless:
            if not self._offscreen:
                texture = self.ctx.texture((w, h), 3)
                self._offscreen = [self.ctx.framebuffer([texture]), texture]
            source = self._offscreen[0]
            self.ctx.copy_framebuffer(source, self.target)
        data = source.read(viewport=(0, 0, w, h), components=3, alignment=1)
        return np.frombuffer(data, np.uint8).reshape(h, w, 3)[::-1].copy()

    # -- programs and lifetime ---------------------------------------------------------------
    def program(self, defines: dict | None = None, **stages: str):
        """A compiled program from shader files on the search path (atmos's ``shaders/``, then the
        directories of :func:`atmos.gpu.add_shader_path`), compiled once per (files, defines), and
        checked by the reference compiler when ``ATMOS_GLSL_CHECK=1`` (:mod:`atmos.gpu.portability`).
        The context owns it: it is released by :meth:`release`, never by its users.

        ``gpu.program(vertex_shader="sky.vert", fragment_shader="sky.frag")`` or
        ``gpu.program(compute_shader="volume.comp", defines={"N": 4})``.
        """
        if self.released:
            self._require_live()
        fast = (tuple(stages.items()), tuple(defines.items()) if defines else ())   # as the caller orders them
        try:
            return self._fast_programs[fast]
        except KeyError:
            pass
        key = (tuple(sorted(stages.items())), tuple(sorted((defines or {}).items())))
        program = self._programs.get(key)
        if program is None:
            sources = load_stages(stages, defines)
            program = compile_program(self.ctx, sources)
            if check_enabled():
                try:
                    check_program(sources)
                except ShaderError:
                    program.release()
                    raise
            self._programs[key] = program
        self._fast_programs[fast] = program
        return program

    @property
    def compiled_files(self) -> set[str]:
        """Names of every shader file compiled so far (tests use this to prove culled passes compile nothing)."""
        return {name for stages, _ in self._programs for _, name in stages}

    def track(self, obj):
        """Register a GL object to be released with this context; returns it."""
        self._require_live()
        self._tracked.add(obj)
        return obj

    def release(self) -> None:
        """Release every tracked object, program and offscreen target, then the context itself
        (a window's context stays its window's). Open Apps on it are closed first (App.close).
        Releasing again does nothing."""
        if self.released:
            return
        failures = []
        for app in list(self._apps):
            try:
                app._closed_by = "by GpuContext.release"
                app.close()
            except Exception as error:         # the App released everything else; so does the context
                failures.append(error)
        self.make_current()
        self.released = True
        for obj in list(self._tracked):
            obj.release()
        for program in self._programs.values():
            extra = program.extra
            for obj in extra.get("owned", ()) if isinstance(extra, dict) else ():
                obj.release()               # what its users keep with it (a block's buffer: own_block)
            program.release()
        for obj in self._offscreen:
            release_gl(obj)
        self._programs.clear()
        self._fast_programs.clear()
        self._offscreen.clear()
        self.queries.clear()
        if self.headless:
            self.ctx.release()
        if failures:
            raise failures[0]

    def check(self, where: str = "") -> None:
        """Raise if OpenGL has recorded an error (``GL_NO_ERROR`` otherwise)."""
        self._require_live()
        error = self.ctx.error
        if error != "GL_NO_ERROR":
            raise GpuError(f"OpenGL error {error}" + (f" after {where}" if where else ""))

    def info(self) -> dict:
        """Renderer, version, whether the renderer is a software rasterizer, and the limits atmos cares about."""
        self._require_live()
        info = self.ctx.info
        keys = ["GL_VENDOR", "GL_RENDERER", "GL_VERSION", "GL_MAX_TEXTURE_SIZE", "GL_MAX_3D_TEXTURE_SIZE",
                "GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS", "GL_MAX_COMPUTE_WORK_GROUP_COUNT",
                "GL_MAX_COMPUTE_WORK_GROUP_SIZE", "GL_MAX_SHADER_STORAGE_BLOCK_SIZE", "GL_MAX_SAMPLES"]
        return {**{k: info[k] for k in keys[:3] if k in info}, "software rasterizer": self.software,
                **{k: info[k] for k in keys[3:] if k in info}}
