"""atmos inside a pyglet window and loop that the game owns: atmos draws the sky and fog, then the game
draws its own pyglet text on top (pyglet's GL error checking stays on: atmos leaves no GL error).

    python examples/pyglet_host.py [FRAMES]
"""
import sys

import pyglet

import atmos
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.window import connect, gl_config

frames = int(sys.argv[1]) if len(sys.argv) > 1 else 0
window = pyglet.window.Window(320, 180, caption="atmos in a pyglet host", resizable=True, config=gl_config())
gpu = atmos.from_current(window.get_framebuffer_size())        # atmos draws into the window's framebuffer
app = atmos.App(gpu).add_plugins(atmos.DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin())
connect(window, app)                                           # keys, mouse, resize, F1 into the App
label = pyglet.text.Label("drawn by the host", x=8, y=8)
drawn = 0


@window.event
def on_draw():
    global drawn
    app.update()
    label.draw()                                               # the host's own GL after atmos's
    drawn += 1
    if frames and drawn >= frames:
        pyglet.app.exit()


pyglet.app.run(interval=0)
app.close()
gpu.release()
window.close()
print(f"host drew {drawn} frames")
