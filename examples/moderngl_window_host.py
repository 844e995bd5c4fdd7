"""atmos inside a moderngl-window ``WindowConfig``: atmos draws the sky and the ground into the window's
framebuffer, then the host draws its own triangle with its own moderngl program on top.

    python examples/moderngl_window_host.py [FRAMES [PNG]]

With FRAMES it closes after that many frames; with PNG it saves the last frame there and prints the
GL error state (the tests run it so under Xvfb).
"""
import sys

import moderngl
import moderngl_window as mglw
import numpy as np

import atmos
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

FRAMES = int(sys.argv[1]) if len(sys.argv) > 1 else 0
PNG = sys.argv[2] if len(sys.argv) > 2 else None

VERTEX = """#version 330
in vec2 in_pos;
void main() { gl_Position = vec4(in_pos, 0.0, 1.0); }
"""
FRAGMENT = """#version 330
out vec4 color;
void main() { color = vec4(1.0, 0.1, 0.1, 1.0); }
"""


class Host(mglw.WindowConfig):
    gl_version = (4, 3)                          # atmos needs compute shaders
    title = "atmos in a moderngl-window host"
    window_size = (320, 180)
    aspect_ratio = None                          # the viewport follows the window, no letterbox
    resizable = True
    vsync = False

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.gpu = atmos.wrap_context(self.ctx, self.wnd.buffer_size)   # atmos on the host's context
        self.app = atmos.App(self.gpu).add_plugins(atmos.DefaultPlugins(overlay=False), SkyGradientPlugin(),
                                                   GroundPlugin())
        self.program = self.ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
        corners = np.array([-0.3, -0.3, 0.3, -0.3, 0.0, 0.3], "f4")
        self.vao = self.ctx.vertex_array(self.program, [(self.ctx.buffer(corners), "2f", "in_pos")])
        self.drawn = 0

    def on_resize(self, width, height):
        self.gpu.resize(self.wnd.buffer_size)     # atmos's frame follows the window

    def on_render(self, time, frame_time):
        self.app.update(frame_time)              # sky and ground into the window's framebuffer
        self.wnd.use()                           # the host's own drawing after atmos's
        self.vao.render(moderngl.TRIANGLES)
        self.drawn += 1
        if FRAMES and self.drawn >= FRAMES:
            if PNG:
                from PIL import Image
                Image.fromarray(self.gpu.read_pixels()).save(PNG)
                print(f"gl error {self.ctx.error}")
            self.wnd.close()

    def on_close(self):
        self.app.close()
        self.gpu.release()
        print(f"host drew {self.drawn} frames")


if __name__ == "__main__":
    mglw.run_window_config(Host, args=["--window", "pyglet"])
