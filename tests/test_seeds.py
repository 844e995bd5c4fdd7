"""``--seed`` reaches what a demo draws at random: the same seed gives byte-identical frames, another
seed other frames (fog_valley's noise once ignored it)."""
import numpy as np
import pytest

from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.runner import build_app


def frame_of(name: str, seed: int) -> np.ndarray:
    gpu = create_headless((64, 36))
    try:
        app = build_app(name, DemoSettings(size=gpu.size, seed=seed, headless=True, frames=2), gpu)
        app.run_frames(2, 1 / 30)
        image = gpu.read_pixels()
        app.close()
        return image
    finally:
        gpu.release()


@pytest.mark.parametrize("name", ["fog_valley", "volumetric_fog", "sky_layer"])
def test_the_seed_decides_the_frames(name):
    first, again, other = frame_of(name, 0), frame_of(name, 0), frame_of(name, 12345)
    assert np.array_equal(first, again), "the same seed gave different frames"
    assert not np.array_equal(first, other), f"--seed has no effect on {name}"
