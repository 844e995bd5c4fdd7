"""The ``atmos`` command: info, demo, graph."""
from __future__ import annotations

import argparse
import os
import sys

from atmos.demo_registry import DEFAULT_DEMO, DemoSettings, list_demos, load_demo


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
        raise argparse.ArgumentTypeError(str(error).removeprefix(f"--out {text}: ")) from None
    return text


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(prog="atmos", description="Real-time atmospheric effects: demos and tools.")
    sub = top.add_subparsers(dest="command", metavar="{info,demo,graph}")
    sub.add_parser("info", help="OpenGL renderer, version and limits")
    demo = sub.add_parser("demo", help="run a demo scene (a window, or headless into a file)")
    demo.add_argument("name", nargs="?", default=DEFAULT_DEMO, help=f"demo name (default: {DEFAULT_DEMO})")
    demo.add_argument("--list", action="store_true", help="list the demos and exit")
    demo.add_argument("--headless", action="store_true", help="render offscreen even when a display exists")
    demo.add_argument("--frames", type=_positive, help="frames to render (headless default: the demo's)")
    demo.add_argument("--size", type=_size, default=(960, 540), help="WxH, default 960x540")
    demo.add_argument("--seed", type=_seed, default=0, help="random seed (default 0)")
    demo.add_argument("--out", type=_out, help="FILE.mp4, FILE.gif, FILE.png (last frame) or a folder of PNGs; "
                                               "headless default: out/NAME.mp4")
    demo.add_argument("--quiet", action="store_true", help="no progress bar")
    graph = sub.add_parser("graph", help="print a demo's compiled render graph")
    graph.add_argument("name", nargs="?", default=DEFAULT_DEMO)
    graph.add_argument("--dot", action="store_true", help="Graphviz dot instead of text")
    return top


def cmd_info(args) -> int:
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    try:
        for k, v in gpu.info().items():
            print(f"{k:40s} {v}")
    finally:
        gpu.release()
    return 0


def cmd_demo(args, top) -> int:
    from atmos.runner import has_display, run_headless, run_window
    if args.list:
        for name, title in list_demos().items():
            print(f"{name:16s} {title}")
        return 0
    try:
        load_demo(args.name)
    except ValueError as error:
        top.error(str(error))
    settings = DemoSettings(size=args.size, seed=args.seed, frames=args.frames,
                            headless=args.headless or not has_display())
    if settings.headless or args.out:
        out = args.out or f"out/{args.name}.mp4"
        result = run_headless(args.name, settings, out, progress=not args.quiet)
        print(f"wrote {result['written']} frames to {result['out']}")
    else:
        run_window(args.name, settings)
    return 0


def cmd_graph(args, top) -> int:
    from atmos.gpu import create_headless
    from atmos.runner import build_app
    try:
        load_demo(args.name)
    except ValueError as error:
        top.error(str(error))
    gpu = create_headless((320, 180))
    app = build_app(args.name, DemoSettings(size=gpu.size, headless=True), gpu, start=False)
    try:
        print(app.graph.to_dot() if args.dot else app.graph.dump())
    finally:
        app.close()
        gpu.release()
    return 0


def main(argv: list[str] | None = None) -> int:
    from atmos.gpu import GpuError, ShaderError
    top = parser()
    args = top.parse_args(argv)
    commands = {"info": lambda: cmd_info(args), "demo": lambda: cmd_demo(args, top),
                "graph": lambda: cmd_graph(args, top)}
    if args.command not in commands:
        top.print_help()
        return 2
    try:
        status = commands[args.command]()
        sys.stdout.flush()
        return status
    except (GpuError, ShaderError) as error:
        print(f"atmos: {error}", file=sys.stderr)
        return 1
    except BrokenPipeError:
        # The reader closed early (`atmos info | head -3`): that is its choice, not our failure.
        # Point stdout at devnull so the interpreter's final flush does not raise again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
