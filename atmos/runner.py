"""Running a demo: in a pyglet window when there is a display, else headless into a file."""
from __future__ import annotations

import os
import sys

from atmos.app import App
from atmos.demo_registry import DemoSettings, load_demo
from atmos.gpu import create_headless, from_current


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")) or sys.platform in ("win32", "darwin")


def build_app(name: str, settings: DemoSettings, gpu, *extra_plugins, start: bool = True) -> App:
    """A started App for demo ``name`` on ``gpu``, with ``extra_plugins`` added after the demo's
    (``start=False``: built and finished, but no system has run — no simulation warm-up)."""
    demo = load_demo(name)
    app = App(gpu)
    app.insert_resource(settings)           # demos read it (headless runs script their camera)
    try:
        demo.build(app, settings)
        app.add_plugins(*extra_plugins)
        app.startup() if start else app.finish()
    except Exception:
        app.close()
        raise
    return app


def run_headless(name: str, settings: DemoSettings, out: str | None, progress: bool = True) -> dict:
    """Render ``settings.frames`` frames at a fixed 1/30 s step; write them to ``out`` if given."""
    from atmos.output import OutputPlugin
    frames = settings.frames or getattr(load_demo(name), "DEFAULT_FRAMES", 90)
    output = OutputPlugin(out) if out else None
    gpu = create_headless(settings.size)
    try:
        app = build_app(name, settings, gpu, *([output] if output else []))
    except Exception:
        gpu.release()
        raise
    writer = output.writer if output else None
    try:
        steps = range(frames)
        if progress:
            from tqdm import tqdm
            steps = tqdm(steps, desc=f"atmos demo {name}", unit="frame", file=sys.stderr)
        for _ in steps:
            app.update(1 / 30)
        gpu.check(f"demo {name}")
        return {"frames": frames, "out": str(writer.path) if writer else None,
                "written": writer.frames_written if writer else 0}
    finally:
        app.close()
        gpu.release()


def slowest_passes(app, n: int = 3) -> str:
    """The ``n`` render passes with the most GPU time (timer queries), e.g. 'clouds 4.1 ms, sky 0.8 ms'."""
    timings = sorted(app.graph.timings.items(), key=lambda kv: -kv[1][0])[:n]
    return ", ".join(f"{name} {gpu_ms:.1f} ms" for name, (gpu_ms, _) in timings)


def run_window(name: str, settings: DemoSettings) -> None:
    """Open a window: ESC quits, F1 toggles the frame-time overlay, WASD/QE + mouse drag fly the camera."""
    import pyglet
    from pyglet.window import key

    from atmos.camera import Input
    from atmos.plugins.overlay import FrameTimes, OverlayPlugin

    config = pyglet.gl.Config(major_version=4, minor_version=3, forward_compatible=True,
                              depth_size=24, double_buffer=True)
    window = pyglet.window.Window(*settings.size, caption=f"atmos — {name}", resizable=True, config=config)
    gpu = from_current(window.get_framebuffer_size())
    app = build_app(name, settings, gpu)
    frames = [0]

    @window.event
    def on_draw():
        app.update()
        frames[0] += 1
        times = app.get_resource(FrameTimes)
        if times is not None and frames[0] % 30 == 0:
            window.set_caption(f"atmos — {name} — {times.summary()} — {slowest_passes(app)}")
        if settings.frames and frames[0] >= settings.frames:
            pyglet.app.exit()  # closing inside on_draw would disturb pyglet's window iteration

    @window.event
    def on_resize(width, height):
        gpu.resize(window.get_framebuffer_size())

    @window.event
    def on_key_press(symbol, modifiers):
        inp = app.resource(Input)
        name_ = key.symbol_string(symbol).lower()
        inp.keys.add(name_)
        inp.pressed.add(name_)
        overlay = next((p for p in app.plugins if isinstance(p, OverlayPlugin)), None)
        if symbol == key.F1 and overlay is not None:
            overlay.configure(visible=not overlay.settings.visible)

    @window.event
    def on_key_release(symbol, modifiers):
        app.resource(Input).keys.discard(key.symbol_string(symbol).lower())

    @window.event
    def on_mouse_drag(x, y, dx, dy, buttons, modifiers):
        inp = app.resource(Input)
        inp.mouse_dx += dx
        inp.mouse_dy += dy

    @window.event
    def on_close():
        app.running = False

    try:
        pyglet.app.run(interval=0)
    finally:
        app.close()
        gpu.release()
        window.close()
