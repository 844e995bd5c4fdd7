"""The pyglet window glue every windowed atmos program uses (``atmos.run``, the demos, your own loop).

:func:`open_window` makes a window with the OpenGL atmos needs; :func:`connect` feeds its events to
an App: keys, mouse and wheel into :class:`atmos.Input`, a resize into ``gpu.resize`` (the frame
fills the new size), F1 shows/hides the frame-time overlay, ESC closes (pyglet's default), losing
focus lets go of held keys. :func:`run_window` is the whole loop.
"""
from __future__ import annotations

import weakref
from typing import Callable


def gl_config():
    """OpenGL 4.3 core (compute shaders), 24-bit depth, double buffered."""
    import pyglet
    return pyglet.gl.Config(major_version=4, minor_version=3, forward_compatible=True, depth_size=24,
                            double_buffer=True)


def open_window(size: tuple[int, int], title: str, resizable: bool = True):
    """A visible pyglet window with :func:`gl_config`; its context is current."""
    import pyglet
    return pyglet.window.Window(*size, caption=title, resizable=resizable, config=gl_config())


class WindowEvents:
    """The handlers :func:`connect` pushes onto a window (``window.remove_handlers(events)`` takes them off)."""

    def __init__(self, window, app):
        self.window, self.app = window, app

    def _tell(self, method: str, *args) -> None:
        """Call ``Input.<method>(*args)`` on the App's Input resource, if it has one."""
        from atmos.input import Input
        inp = self.app.get_resource(Input)
        if inp is not None:
            getattr(inp, method)(*args)

    def on_key_press(self, symbol, modifiers):
        self._tell("press", symbol)

    def on_key_release(self, symbol, modifiers):
        self._tell("release", symbol)

    def on_mouse_motion(self, x, y, dx, dy):
        self._tell("move_mouse", x, y, dx, dy)

    def on_mouse_drag(self, x, y, dx, dy, buttons, modifiers):
        self.on_mouse_motion(x, y, dx, dy)

    def on_mouse_press(self, x, y, button, modifiers):
        self._tell("press_button", button)

    def on_mouse_release(self, x, y, button, modifiers):
        self._tell("release_button", button)

    def on_mouse_scroll(self, x, y, scroll_x, scroll_y):
        self._tell("scroll", scroll_y, scroll_x)

    def on_deactivate(self):
        self._tell("clear")

    def on_resize(self, width, height):
        self.app.gpu.resize(self.window.get_framebuffer_size())


_CONNECTED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def connect(window, app) -> WindowEvents:
    """Feed ``window``'s events to ``app`` (see the module docstring); returns the handlers, which live
    as long as the window (pyglet holds handler methods weakly)."""
    events = WindowEvents(window, app)
    window.push_handlers(events)
    _CONNECTED[window] = events
    return events


def run_window(build: Callable, size: tuple[int, int], title: str, frames: int | None = None,
               on_frame: Callable | None = None) -> None:
    """Open a window, make the App with ``build(gpu)`` on its context, connect it and run until the
    window closes (or ``frames`` frames were drawn). ``on_frame(app, window, frame)`` runs after each."""
    import pyglet

    from atmos.gpu import from_current

    window = open_window(size, title)
    gpu = app = None
    try:
        gpu = from_current(window.get_framebuffer_size())
        app = build(gpu)
        connect(window, app)
        drawn = [0]

        @window.event
        def on_draw():
            app.update()
            drawn[0] += 1
            if on_frame is not None:
                on_frame(app, window, drawn[0])
            if not app.running or (frames and drawn[0] >= frames):
                pyglet.app.exit()   # closing inside on_draw would disturb pyglet's window iteration

        pyglet.app.run(interval=0)
    finally:
        if app is not None:
            app.close()
        if gpu is not None:
            gpu.release()
        window.close()
