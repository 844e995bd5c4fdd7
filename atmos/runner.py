"""Running a game or demo (``build(app, settings)``): in a pyglet window when a display can be reached,
else headless into a file. ``atmos.run`` and the ``atmos run`` / ``atmos demo`` commands come here."""
from __future__ import annotations

import os
import sys

from atmos.app import App
from atmos.demo_registry import CLOUD_RENDERERS, DEFAULT_CLOUDS, EXPOSURES, HAZES, SKY_MODELS, DemoSettings, haze_conflict, load_demo
from atmos.gpu import create_headless

_FILES: dict = {}      # game files loaded so far, by resolved path: each runs once per process


def display_problem() -> str | None:
    """None when a window can open here; else why not, in words (no DISPLAY, or a DISPLAY that no X
    server answers: pyglet draws windows through X11 on Linux, Xwayland under Wayland)."""
    if sys.platform in ("win32", "darwin"):
        return None
    name = os.environ.get("DISPLAY")
    if not name:
        if os.environ.get("WAYLAND_DISPLAY"):
            return "WAYLAND_DISPLAY is set but DISPLAY is not (pyglet needs X11: start Xwayland)"
        return "no display (DISPLAY is not set)"
    import ctypes
    import ctypes.util
    library = ctypes.util.find_library("X11")
    if library is None:
        return f"DISPLAY={name} is set but libX11 is not installed"
    x11 = ctypes.CDLL(library)
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    connection = x11.XOpenDisplay(name.encode())
    if not connection:
        return f"DISPLAY={name} is set but no X server answers there"
    x11.XCloseDisplay(connection)
    return None


def load_game(game):
    """The module or object with ``build(app, settings)`` that ``game`` names: a demo name, a path to a
    ``.py`` file (``atmos run game.py``), a module, or a ``build(app, settings)`` function itself."""
    if callable(game) and not isinstance(game, type):
        return _Built(game)
    if isinstance(game, (str, os.PathLike)) and (str(game).endswith(".py") or os.sep in str(game)):
        return load_game_file(os.fspath(game))
    if isinstance(game, str):
        return load_demo(game)
    if callable(getattr(game, "build", None)):
        return game
    raise ValueError(f"expected a demo name, a path to a .py file, a module with build(app, settings) or such a "
                     f"function, got {game!r}")


class _Built:
    """A bare ``build(app, settings)`` function seen as a game module."""

    def __init__(self, build):
        self.build = build
        self.TITLE = getattr(build, "__doc__", None) or getattr(build, "__name__", "atmos")
        self.__name__ = getattr(build, "__module__", "game")


def load_game_file(path: str):
    """Run the game file at ``path`` (once per process) and return it as a module; ValueError unless it
    is a ``.py`` file that defines ``build(app, settings)``."""
    import importlib.util
    from pathlib import Path
    file = Path(path)
    if file.suffix != ".py" or not file.is_file():
        raise ValueError(f"{path}: no such .py file (atmos run takes a Python file that defines build(app, settings))")
    if file.resolve() in _FILES:
        return _FILES[file.resolve()]
    folder = str(file.resolve().parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)          # the game may import its neighbours, as a script would
    name = f"atmos_game_{file.stem}"       # never shadows a module of the same stem (random.py)
    spec = importlib.util.spec_from_file_location(name, file)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module              # dataclasses in the game look their module up there
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    if not callable(getattr(module, "build", None)):
        raise ValueError(f"{path} defines no build(app, settings) function; atmos run needs one, as a demo has")
    _FILES[file.resolve()] = module
    return module


def title_of(game) -> str:
    module = load_game(game)
    return getattr(module, "TITLE", None) or getattr(module, "__name__", "atmos")


def build_app(name, settings: DemoSettings, gpu, *extra_plugins, start: bool = True, script=None) -> App:
    """A started App for ``name`` (a demo, a game file or module, a build function: :func:`load_game`)
    on ``gpu``, with ``extra_plugins`` added after the game's (``start=False``: built and finished,
    but no system has run — no simulation warm-up); ``script``: :mod:`atmos.script`'s step, run first
    every frame."""
    from atmos.script import ScriptPlugin
    demo = load_game(name)
    scripted = ScriptPlugin(script) if script is not None else None      # a bad script fails before the App
    app = App(gpu)
    app.insert_resource(settings)           # demos read it (headless runs script their camera)
    try:
        if scripted is not None:
            app.add_plugins(scripted)
        demo.build(app, settings)
        app.add_plugins(*extra_plugins)
        app.startup() if start else app.finish()
    except Exception as error:
        _close_after(app, error, "closing the half-built App also failed")
        raise
    return app


def _close_after(app: App, error: BaseException, note: str) -> None:
    """Close ``app`` after ``error``; a failure to close becomes a note on ``error`` (the one to show)."""
    try:
        app.close()
    except Exception as failure:
        error.add_note(f"{note}: {failure}")


def run_headless(name, settings: DemoSettings, out: str | None, progress: bool = True, script=None,
                 shots=None) -> dict:
    """Render ``settings.frames`` frames of ``name`` (:func:`load_game`) at a fixed 1/30 s step; write
    them to ``out`` if given (only the frame numbers ``shots``, into a folder, when given); ``script``:
    a scripted player (:mod:`atmos.script`). Interrupted (Ctrl-C), the file is completed with the frames
    rendered so far, as ffmpeg does (:class:`Interrupted` says how many); a failed run leaves none."""
    from atmos.output import OutputPlugin, check_shots
    frames = settings.frames or getattr(load_game(name), "DEFAULT_FRAMES", 90)
    shots = check_shots(shots, frames)
    if shots is not None and out is None:
        raise ValueError("shots need an output folder to write them to (--out frames/)")
    output = OutputPlugin(out, shots=shots) if out is not None else None   # the path is checked here, before rendering
    gpu = create_headless(settings.size)
    try:
        app = build_app(name, settings, gpu, *([output] if output else []), script=script)
    except Exception:
        gpu.release()
        raise
    writer = output.writer if output else None
    try:
        steps = range(frames)
        if progress:
            from tqdm import tqdm
            steps = tqdm(steps, desc=f"atmos {_label(name)}", unit="frame", file=sys.stderr)
        for _ in steps:
            app.update(1 / 30)
        gpu.check(_label(name))
        if writer is not None:
            writer.close()                            # completes the output file (OutputError if it cannot)
        return {"frames": frames, "out": str(writer.path) if writer else None,
                "written": writer.frames_written if writer else 0}
    except KeyboardInterrupt:
        if writer is not None and writer.frames_written:
            writer.close()                            # a valid file of the frames so far (OutputError if not)
            raise Interrupted(f"interrupted; wrote the {writer.frames_written} frame(s) rendered so far to "
                              f"{writer.path}") from None
        if writer is not None:
            writer.abort()
        raise Interrupted("interrupted before any frame was written; nothing was left behind") from None
    except BaseException as error:
        if writer is not None:
            writer.abort()                            # a failed run leaves no file behind
        _close_after(app, error, "closing the App also failed")
        raise
    finally:
        try:
            app.close()
        finally:
            gpu.release()


class Interrupted(KeyboardInterrupt):
    """A headless run stopped by Ctrl-C; the message says what was written."""


def slowest_passes(app, n: int = 3) -> str:
    """The ``n`` render passes with the most GPU time (timer queries), e.g. 'clouds 4.1 ms, sky 0.8 ms';
    empty while nothing turns timings on (``app.graph.timings_enabled``, the overlay when shown)."""
    timings = sorted(app.graph.timings.items(), key=lambda kv: -kv[1][0])[:n]
    return ", ".join(f"{name} {gpu_ms:.1f} ms" for name, (gpu_ms, _) in timings)


def _label(game) -> str:
    return f"demo {game}" if isinstance(game, str) and not game.endswith(".py") else str(getattr(game, "__name__", game))


def run_window(name, settings: DemoSettings, title: str | None = None, script=None) -> None:
    """``name`` (:func:`load_game`) in a window (:mod:`atmos.window`: ESC quits, F1 the overlay);
    the caption shows the frame times, and the slowest passes while the overlay shows."""
    from atmos.overlay import FrameTimes
    from atmos.window import run_window as window_loop

    caption = title or f"atmos — {name}"

    def show_times(app, window, frame):
        times = app.get_resource(FrameTimes)
        if times is not None and frame % 30 == 0:
            passes = slowest_passes(app)
            window.set_caption(f"{caption} — {times.summary()}" + (f" — {passes}" if passes else ""))

    window_loop(lambda gpu: build_app(name, settings, gpu, script=script), settings.size, caption, settings.frames,
                show_times)


def run(game, *, size: tuple[int, int] = (960, 540), title: str | None = None, headless: bool | None = None,
        frames: int | None = None, out: str | None = None, seed: int = 0, clouds: str = DEFAULT_CLOUDS,
        sky: str = "physical", haze: str = "fog", exposure: str = "auto", progress: bool = False, script=None, shots=None) -> dict | None:
    """Run a game: ``game`` is ``build(app, settings)`` (a function, a module that defines it, a path
    to a ``.py`` file, or a demo name). The App is made for you on a window's context (the window must
    exist before the GL context, so atmos makes both), or on a headless one when ``headless`` is True,
    when ``out`` is given, or when no display can be reached (a notice on stderr says why).

    ``settings`` (:class:`atmos.DemoSettings`) carries ``size``, ``seed``, ``frames``, ``headless`` and
    ``clouds``: the cloud renderer a cloud scene uses, "march" (the ray march, the default) or "sprites"
    (the thesis's point sprites), like ``atmos demo --clouds`` (the demos ``sunset``, ``flight`` and ``weather`` read it);
    ``sky``: "preetham" or "physical", like ``atmos demo --sky`` (the demos with a sky read it);
    ``haze``: "fog", "air" (the physical sky's aerial perspective) or "both", like ``atmos demo --haze``.
    ``exposure``: "auto" (a metered, adapting physical camera with bloom) or "fixed", like ``atmos demo --exposure``.
    Headless: ``frames`` frames (default the game's ``DEFAULT_FRAMES`` or 90) at 1/30 s, written to
    ``out`` (``.mp4``, ``.gif``, ``.png`` or a folder) if given, only the frame numbers ``shots`` (into
    a folder) when given; returns what was written. Windowed: until the window closes (or ``frames``
    frames); returns None. ``script``: ``step(app, frame)`` or a ``.py`` file defining it, run first every
    frame to play the game (:mod:`atmos.script`)."""
    from atmos.checks import check_choice
    from atmos.gpu.context import check_frame_size
    load_game(game)                                   # a bad game fails here, before any window
    if script is not None:
        from atmos.script import load_script
        load_script(script)                           # and a bad script
    size = check_frame_size(size, None, "atmos.run size")
    clouds = check_choice("atmos.run", "clouds", clouds, CLOUD_RENDERERS)
    sky = check_choice("atmos.run", "sky", sky, SKY_MODELS)
    haze = check_choice("atmos.run", "haze", haze, HAZES)
    exposure = check_choice("atmos.run", "exposure", exposure, EXPOSURES)
    conflict = haze_conflict(haze, sky)
    if conflict:
        raise ValueError(f"atmos.run haze={haze!r} is {conflict}")
    if headless is None:
        problem = display_problem()
        headless = problem is not None
        if problem is not None:
            print(f"atmos: {problem}; rendering headless" + (f" into {out}" if out else ""), file=sys.stderr)
    settings = DemoSettings(size=size, seed=seed, frames=frames, clouds=clouds, sky=sky, haze=haze, exposure=exposure,
                            headless=bool(headless) or out is not None)
    if settings.headless:
        return run_headless(game, settings, out, progress=progress, script=script, shots=shots)
    if shots is not None:
        raise ValueError("shots are for headless runs into a folder (out='frames/')")
    run_window(game, settings, title or title_of(game), script=script)
    return None
