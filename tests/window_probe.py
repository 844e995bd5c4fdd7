"""Run under a (virtual) X display by tests/test_window.py: a real pyglet window through atmos.window,
resized while running, with pyglet's GL error checking on, the render graph's timer queries on (read
through GLX's functions here). Prints one JSON line of what it saw.

    python tests/window_probe.py OUT_DIR
"""
import json
import sys

import pyglet

pyglet.options["debug_gl"] = True          # every pyglet GL call raises on a pending GL error

from atmos.demo_registry import DemoSettings  # noqa: E402
from atmos.gpu import queries  # noqa: E402
from atmos.runner import build_app  # noqa: E402
from atmos.window import run_window  # noqa: E402

SIZES = [(200, 120), (320, 240), (160, 200)]
FRAMES_PER_SIZE = 6


def main(out_dir: str) -> None:
    from PIL import Image
    seen = []
    label = []

    def on_frame(app, window, frame):
        if not label:                                  # made in the window's context
            label.append(pyglet.text.Label("atmos", x=4, y=4))
            app.graph.timings_enabled = True
        step, at = divmod(frame, FRAMES_PER_SIZE)
        if at == FRAMES_PER_SIZE - 1:                  # the last frame at this size: look at it
            pixels = app.gpu.read_pixels()
            error = app.gpu.ctx.error
            label[0].draw()                             # pyglet after atmos: raises if a GL error was left
            Image.fromarray(pixels).save(f"{out_dir}/window_{pixels.shape[1]}x{pixels.shape[0]}.png")
            seen.append({"size": list(window.get_framebuffer_size()), "pixels": list(pixels.shape[1::-1]),
                         "dark": float((pixels.max(-1) < 8).mean()), "error": error})
            if step + 1 < len(SIZES):
                window.set_size(*SIZES[step + 1])
            else:
                timers.update(apis=[api for api, gl in queries._LOADED.items() if gl is not None],
                              ms={name: value[0] for name, value in app.graph.timings.items()})
                app.running = False

    timers = {}
    settings = DemoSettings(size=SIZES[0], frames=None, headless=False)
    run_window(lambda gpu: build_app("testbed", settings, gpu), SIZES[0], "atmos window probe", None, on_frame)
    print(json.dumps({"seen": seen, "timers": timers}))


if __name__ == "__main__":
    main(sys.argv[1])
