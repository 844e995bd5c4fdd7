"""Every demo renders a few headless frames that are not blank (the CLI tests cover the file output)."""
import pytest

from atmos.demo_registry import DemoSettings, list_demos
from atmos.gpu import create_headless
from atmos.runner import build_app


@pytest.mark.parametrize("name", sorted(list_demos()))
def test_demo_renders_frames(name):
    gpu = create_headless((96, 54))
    try:
        app = build_app(name, DemoSettings(size=gpu.size, headless=True, frames=3), gpu)
        app.run_frames(4, 1 / 30)
        image = gpu.read_pixels().astype(float)
        assert gpu.ctx.error == "GL_NO_ERROR"
        assert image.std() > 3, f"demo {name} renders a blank image"
        app.close()
    finally:
        gpu.release()
