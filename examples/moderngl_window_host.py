"""atmos inside a moderngl-window ``WindowConfig``: atmos draws the sky and the ground into the window's
framebuffer, then the host draws its own triangle with its own moderngl program on top. The window's
keys, mouse and wheel go to atmos's ``Input`` (WASD/QE and a mouse drag fly the camera).

    python examples/moderngl_window_host.py [FRAMES [PNG]]

With FRAMES it closes after that many frames; with PNG it also sends pyglet events (W held, a left
click) through the window on its second frame, saves the last frame there and prints what atmos's
Input saw and the GL error state (the tests run it so under Xvfb).
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
BUTTONS = {1: atmos.mouse.LEFT, 2: atmos.mouse.RIGHT, 3: atmos.mouse.MIDDLE}   # moderngl-window's -> pyglet's

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

    # -- input: the pyglet backend's key codes are pyglet's, as atmos.key; y goes up from the bottom --
    def on_key_event(self, key, action, modifiers):
        inp = self.app.resource(atmos.Input)
        inp.press(key) if action == self.wnd.keys.ACTION_PRESS else inp.release(key)

    def on_mouse_position_event(self, x, y, dx, dy):
        self.app.resource(atmos.Input).move_mouse(x, self.wnd.height - y, dx, -dy)

    on_mouse_drag_event = on_mouse_position_event

    def on_mouse_press_event(self, x, y, button):
        if button in BUTTONS:
            self.app.resource(atmos.Input).press_button(BUTTONS[button])

    def on_mouse_release_event(self, x, y, button):
        if button in BUTTONS:
            self.app.resource(atmos.Input).release_button(BUTTONS[button])

    def on_mouse_scroll_event(self, x_offset, y_offset):
        self.app.resource(atmos.Input).scroll(y_offset, x_offset)

    def on_render(self, time, frame_time):
        if PNG and self.drawn == 1:              # the test: real pyglet events through the window
            self.start = self.app.resource(atmos.Camera).position.copy()
            self.wnd._window.dispatch_event("on_key_press", atmos.key.W, 0)
            self.wnd._window.dispatch_event("on_mouse_press", 10, 10, atmos.mouse.LEFT, 0)
        self.app.update(frame_time)              # sky and ground into the window's framebuffer
        self.wnd.use()                           # the host's own drawing after atmos's
        self.vao.render(moderngl.TRIANGLES)
        self.drawn += 1
        if FRAMES and self.drawn >= FRAMES:
            if PNG:
                from PIL import Image
                Image.fromarray(self.gpu.read_pixels()).save(PNG)
                inp = self.app.resource(atmos.Input)
                moved = float(((self.app.resource(atmos.Camera).position - self.start) ** 2).sum() ** 0.5)
                print(f"input keys {sorted(inp.keys)} buttons {sorted(inp.buttons)} camera moved {moved:.3f}")
                print(f"gl error {self.ctx.error}")
            self.wnd.close()

    def on_close(self):
        self.app.close()
        self.gpu.release()
        print(f"host drew {self.drawn} frames")


if __name__ == "__main__":
    mglw.run_window_config(Host, args=["--window", "pyglet"])
