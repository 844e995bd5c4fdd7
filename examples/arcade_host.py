"""atmos inside an Arcade window: atmos draws the sky and clouds, then Arcade draws its own sprite and
text on top (pyglet's GL error checking stays on: atmos leaves no GL error).

    python examples/arcade_host.py [FRAMES [PNG]]

With FRAMES it closes after that many frames; with PNG it saves the last frame there and prints the
GL error state (the tests run it so under Xvfb).
"""
import sys

import arcade

import atmos
from atmos.plugins.clouds.presets import CloudSky
from atmos.plugins.sky import SkyPlugin
from atmos.window import connect

FRAMES = int(sys.argv[1]) if len(sys.argv) > 1 else 0
PNG = sys.argv[2] if len(sys.argv) > 2 else None


class Host(arcade.Window):
    def __init__(self):
        super().__init__(320, 180, "atmos in an Arcade host", resizable=True, gl_version=(4, 3))  # compute
        self.gpu = atmos.from_current(self.get_framebuffer_size())      # Arcade's context, its screen
        self.app = atmos.App(self.gpu).add_plugins(atmos.DefaultPlugins(overlay=False), SkyPlugin(),
                                                   CloudSky("fair_weather"))
        connect(self, self.app)                                          # keys, mouse, resize into the App
        self.app.resource(atmos.Camera).pitch = 0.25                     # look up into the clouds
        self.sprites = arcade.SpriteList()
        self.sprites.append(arcade.SpriteSolidColor(60, 40, 160, 50, color=arcade.color.RED))
        self.text = arcade.Text("drawn by Arcade", 8, 8, arcade.color.YELLOW, 14)
        self.drawn = 0

    def on_draw(self):
        self.app.update()                        # atmos fills the window: sky, clouds, tone mapping
        self.ctx.reset()                         # Arcade's own state again (it caches what it set)
        self.sprites.draw()
        self.text.draw()
        self.drawn += 1
        if FRAMES and self.drawn >= FRAMES:
            if PNG:
                arcade.get_image().convert("RGB").save(PNG)
                print(f"gl error {self.ctx.error or 'GL_NO_ERROR'}")
            self.close()


if __name__ == "__main__":
    host = Host()
    arcade.run()
    host.app.close()
    host.gpu.release()
    print(f"host drew {host.drawn} frames")
