"""The ``atmos`` command: info, demo, run, graph."""
from __future__ import annotations

import argparse
import os
import sys

from atmos.demo_registry import (CLOUD_RENDERERS, DEFAULT_CLOUDS, DEFAULT_DEMO, EXPOSURES, HAZES, SKY_MODELS, DemoSettings, haze_conflict,
                                 list_demos, load_demo)


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WxH; give two positive integers such as 1280x720") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"{text!r}: width and height must be between 1 and 16384")
    return w, h


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not allowed; give 1 or more")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer seed") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"{value} is out of range; seeds are 0 .. 4294967295")
    return value


def _out(text: str) -> str:
    from atmos.output import output_kind
    try:
        output_kind(text)
    except ValueError as error:
        message = str(error)
        raise argparse.ArgumentTypeError(message.split(": ", 1)[1] if message.startswith("--out ") else message) from None
    return text


_VALUED = ("--size", "--frames", "--seed")


def _negative_values(argv: list[str]) -> list[str]:
    """``--size -5x10`` as ``--size=-5x10``: argparse would take a value starting with '-' for an
    option and say only "expected one argument"; joined, the option's own check names what is allowed."""
    out = []
    for token in argv:
        if out and out[-1] in _VALUED and token[:1] == "-" and token[1:2].isdigit():
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(prog="atmos", description="Real-time atmospheric effects: demos and tools.")
    sub = top.add_subparsers(dest="command", metavar="{info,demo,run,graph}")
    sub.add_parser("info", help="OpenGL renderer, version and limits")
    demo = sub.add_parser("demo", help="run a demo scene (a window, or headless into a file)")
    demo.add_argument("name", nargs="?", default=DEFAULT_DEMO, help=f"demo name (default: {DEFAULT_DEMO})")
    demo.add_argument("--list", action="store_true", help="list the demos and exit")
    _run_options(demo, "demo's")
    game = sub.add_parser("run", help="run your game: a .py file that defines build(app, settings)")
    game.add_argument("file", help="path to the game's Python file")
    _run_options(game, "game's DEFAULT_FRAMES or 90")
    graph = sub.add_parser("graph", help="print a demo's compiled render graph")
    graph.add_argument("name", nargs="?", default=DEFAULT_DEMO)
    graph.add_argument("--dot", action="store_true", help="Graphviz dot instead of text")
    graph.add_argument("--png", metavar="PATH", help="also draw the frame to a PNG (passes by phase, resources, lifetimes)")
    _clouds_option(graph)
    return top


def _run_options(command, frames_default: str) -> None:
    """The options ``atmos demo`` and ``atmos run`` share."""
    command.add_argument("--headless", action="store_true", help="render offscreen even when a display exists")
    command.add_argument("--frames", type=_positive, help=f"frames to render (headless default: the {frames_default})")
    command.add_argument("--size", type=_size, default=(960, 540), help="WxH, default 960x540")
    command.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    command.add_argument("--out", type=_out, help="FILE.mp4, FILE.gif, FILE.png (last frame) or a folder of PNGs; "
                                                  "headless default: out/NAME.mp4")
    command.add_argument("--shots", metavar="N,N,...", help="headless: write only these frame numbers (from 0), "
                                                            "one PNG each into the --out folder")
    command.add_argument("--script", metavar="FILE.py", help="play the game with FILE.py's step(app, frame), run "
                                                             "first every frame (press keys through atmos.Input)")
    _clouds_option(command)
    command.add_argument("--quiet", action="store_true", help="no progress bar")


def _clouds_option(command) -> None:
    command.add_argument("--clouds", choices=CLOUD_RENDERERS, default=DEFAULT_CLOUDS,
                         help="cloud renderer of the cloud scenes (sunset, flight, weather): point sprites "
                              f"or the ray march (default {DEFAULT_CLOUDS}; key C flips it in a window, key X the sprites "
                              "between compute splatting and blended points)")
    command.add_argument("--sky", choices=SKY_MODELS, default="physical",
                         help="sky model of the demos with a sky: the Preetham analytic sky or the physical "
                              "atmosphere after Hillaire 2020, which also lights the sun and ambient (default physical)")
    command.add_argument("--haze", choices=HAZES, default="fog",
                         help="distance haze of the hazy demos (sunset, flight): an exponential fog toward the "
                              "sky's colour, the physical sky's aerial perspective, Earth's own air, or both mixed "
                              "along each ray (air and both need --sky physical; default fog)")
    command.add_argument("--exposure", choices=EXPOSURES, default="auto",
                         help="camera of the outdoor demos (sunset, flight, weather, sky_day): metered, adapting "
                              "EV100 with bloom, or the fixed exposure 1 (default auto)")


def cmd_info(args) -> int:
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    try:
        for k, v in gpu.info().items():
            if k == "software rasterizer":
                v = "yes: correct, but frames are slow (a GPU driver with OpenGL 4.3 makes them real time)" if v else "no"
            print(f"{k:40s} {v}")
    finally:
        gpu.release()
    return 0


def cmd_demo(args, top) -> int:
    if args.list:
        for name, title in list_demos().items():
            print(f"{name:16s} {title}")
        return 0
    try:
        load_demo(args.name)
    except ValueError as error:
        top.error(str(error))
    return _play(args, args.name, args.name)


def cmd_run(args, top) -> int:
    from pathlib import Path

    from atmos.runner import load_game_file
    try:
        load_game_file(args.file)
    except ValueError as error:
        top.error(str(error))
    return _play(args, args.file, Path(args.file).stem)


def _play(args, game, stem: str) -> int:
    """A window, or headless into ``--out`` (default out/STEM.mp4) when asked, when ``--out`` is given
    or when no display can be reached (a notice says why)."""
    from atmos.runner import display_problem, run_headless, run_window
    problem = None if args.headless else display_problem()
    if problem is not None:
        print(f"atmos: {problem}; rendering headless", file=sys.stderr)
    settings = DemoSettings(size=args.size, seed=args.seed, frames=args.frames, clouds=args.clouds, sky=args.sky,
                            haze=args.haze, exposure=args.exposure, headless=args.headless or args.out is not None or problem is not None)   # as atmos.run
    if settings.headless:
        out = args.out if args.out is not None else (f"out/{stem}/" if args.shots else f"out/{stem}.mp4")
        result = run_headless(game, settings, out, progress=not args.quiet, script=args.script, shots=args.shots)
        print(f"wrote {result['written']} frames to {result['out']}")
    else:
        if args.shots:
            raise ValueError("--shots is for headless runs (add --headless)")
        run_window(game, settings, script=args.script)
    return 0


def cmd_graph(args, top) -> int:
    from atmos.gpu import create_headless
    from atmos.runner import build_app
    try:
        load_demo(args.name)
    except ValueError as error:
        top.error(str(error))
    gpu = create_headless((320, 180))
    app = build_app(args.name, DemoSettings(size=gpu.size, headless=True, clouds=args.clouds, sky=args.sky,
                                                 haze=args.haze, exposure=args.exposure), gpu, start=False)
    try:
        print(app.graph.to_dot() if args.dot else app.graph.dump())
        if args.png:
            app.graph.picture(f"atmos graph {args.name}: one frame").save(args.png)
            print(f"wrote {args.png}")
    finally:
        app.close()
        gpu.release()
    return 0


def main(argv: list[str] | None = None) -> int:
    """Exit status 0 on success, 2 for bad arguments, 1 when the run failed (no GPU, a shader, the
    output cannot be written, a setting refused): a one-line message, no traceback (ATMOS_TRACEBACK=1
    shows it)."""
    from atmos.app import AppError
    from atmos.gpu import GpuError, ShaderError
    from atmos.output import OutputError
    top = parser()
    args = top.parse_args(_negative_values(sys.argv[1:] if argv is None else list(argv)))
    haze = getattr(args, "haze", "fog")
    conflict = haze_conflict(haze, getattr(args, "sky", "physical"))
    if conflict:
        top.error(f"--haze {haze} is {conflict} (--sky physical)")
    commands = {"info": lambda: cmd_info(args), "demo": lambda: cmd_demo(args, top), "run": lambda: cmd_run(args, top),
                "graph": lambda: cmd_graph(args, top)}
    if args.command not in commands:
        top.print_help()
        return 2
    try:
        status = commands[args.command]()
        sys.stdout.flush()
        return status
    except (GpuError, ShaderError, OutputError, AppError, ValueError) as error:
        if os.environ.get("ATMOS_TRACEBACK"):
            raise
        print(f"atmos: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as interrupt:
        print(f"atmos: {interrupt or 'interrupted'}", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader closed early (`atmos info | head -3`): that is its choice, not our failure.
        # Point stdout at devnull so the interpreter's final flush does not raise again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
