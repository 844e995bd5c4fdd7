"""Clouds to the horizon: the volume's edge fade, the far field's cover, and the sunset horizon by pixels."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.plugins.cloud_far_field import CloudFarFieldPlugin
from atmos.plugins.cloud_far_field.reference import column_quantiles, volume_cover
from atmos.plugins.clouds import CloudSimulation
from atmos.plugins.clouds.edge import edge_weight
from atmos.runner import build_app


def test_edge_weight_is_one_inside_zero_on_the_circle_and_smooth():
    uv = np.stack([np.linspace(0.5, 1.0, 101), np.full(101, 0.5)], -1)
    w = edge_weight(uv, 0.4)
    assert w[0] == 1.0 and w[60] == 1.0 and w[-1] == 0.0
    assert np.all(np.diff(w) <= 0.0) and np.abs(np.diff(w)).max() < 0.05       # no step
    assert edge_weight([[1.0, 1.0]], 0.4)[0] == 0.0                             # the square's corners are gone
    assert np.all(edge_weight(np.random.default_rng(0).random((50, 2)), 0.0) == 1.0)


def test_sunset_has_clouds_below_9_degrees_around_the_sun_and_cover_matches_numpy():
    gpu = create_headless((160, 90))
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True), gpu)
    try:
        app.run_frames(4, 1 / 30)
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sim = app.resource(CloudSimulation)
        sets = sim.sets()
        gpu_cover, gpu_columns = far.layer.read_cover()
        sums = [sets.maps_of(s).read_sums()[0] for s in (sets.a, sets.b)]
        expected = volume_cover(sums[0], sums[1], sets.t, sets.a_shift, sim.settings.cover_threshold,
                                sim.settings.edge_fade)
        assert 0.0 < expected < 1.0 and abs(gpu_cover - expected) < 1e-4
        # the column-sum quantiles the march's far field takes (cover.comp's histogram: within a bin)
        columns = column_quantiles(sums[0], sums[1], sets.t, sets.a_shift, sim.settings.edge_fade)
        bin_width = sets.shape[1] / 256
        assert columns[-1] > 1.0 and np.all(np.diff(gpu_columns) >= 0.0)
        assert np.abs(gpu_columns - columns).max() < 1.5 * bin_width, np.c_[gpu_columns, columns]
        assert abs(np.mean(gpu_columns > sim.settings.cover_threshold) - expected) < 2.0 / 32   # covered at the same ranks
        cam = app.resource(Camera)
        with_far = app.read_linear()
        far.configure(enabled=False)
        app.render()
        without = app.read_linear()
        # rows of the sky between 0.5° and 9° above the horizon (the camera's pitch is 7°)
        rows = np.arange(gpu.size[1])
        elevation = cam.pitch + np.arctan((1.0 - 2.0 * (rows + 0.5) / gpu.size[1]) * math.tan(cam.fov_y / 2))
        band = (elevation > math.radians(0.5)) & (elevation < math.radians(9.0))
        changed = np.abs(with_far[band, :, :3] - without[band, :, :3]).max(-1) > 0.02
        assert changed.mean() > 0.05, f"only {changed.mean():.1%} of the low sky has far-field clouds"
    finally:
        app.close()
        gpu.release()
