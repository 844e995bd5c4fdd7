"""The physical camera: the GPU's luminance histogram, metered and adapted EV100, bloom chain and the
present's mix against their float64 twins (plugins/physical_camera/reference.py) on fresh random
frames; the exposure followed over time; settings, extremes and culling."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.graph import RenderPass
from atmos.plugins.physical_camera import PhysicalCameraPlugin, PhysicalCameraSettings
from atmos.plugins.physical_camera import reference as ref
from atmos.plugins.physical_camera.plugin import HISTOGRAM
from atmos.render_core import BLOOM, COLOR, RenderCorePlugin, present_levels


class ImagePass(RenderPass):
    """Overwrites ``color`` with ``image`` (float16 (h, w, 4), rows bottom-up), changeable between frames."""
    name = "image"
    phase = "opaque"

    def __init__(self, image):
        self.image = image

    def setup(self, builder) -> None:
        builder.write(COLOR)

    def execute(self, frame) -> None:
        frame.resource(COLOR).write(np.ascontiguousarray(self.image, np.float16).tobytes())


def hdr_image(rng, shape, ev_range=(-6.0, 14.0)):
    """float16 (h, w, 4) grey-ish HDR pixels whose EV100 spread over and past the range, none within
    1e-3 of a bin's edge (float32 vs float64 may put those either side)."""
    h, w = shape
    lo, hi = ev_range
    ev = rng.uniform(lo - 2.0, hi + 2.0, (h, w))
    tint = rng.uniform(0.7, 1.3, (h, w, 3))
    for _ in range(20):
        rgb = (np.exp2(ev - ref.EV_OFFSET)[..., None] * tint).astype(np.float16).astype(np.float64)
        e = ref.ev100_of(ref.luminance(rgb))
        place = (e - lo) / (hi - lo) * (ref.BINS - 1)
        bad = (np.abs(place - np.round(place)) < 1e-3 * (ref.BINS - 1) / (hi - lo)) | (np.abs(e - lo) < 1e-3)
        if not bad.any():
            break
        ev = np.where(bad, rng.uniform(lo - 2.0, hi + 2.0, (h, w)), ev)
    rgb[rng.uniform(size=(h, w)) < 0.02] = 0.0                              # black pixels: bin 0
    return np.concatenate([rgb, np.ones((h, w, 1))], -1).astype(np.float16)


class ProbePass(RenderPass):
    """Reads resources back after the frame (phase readback): ``data[name]`` = their bytes."""
    name = "probe"
    phase = "readback"

    def __init__(self, *names):
        self.names, self.data = names, {}

    def setup(self, builder) -> None:
        for name in self.names:
            builder.read(name, access="storage" if name == HISTOGRAM else None)
        builder.side_effect()

    def execute(self, frame) -> None:
        for name in self.names:
            resource = frame.resource(name)
            frame.gpu.hazards.use(reads=[(resource, "copy")])
            self.data[name] = (resource.read(), getattr(resource, "size", None))


def ran(app) -> set:
    return {p.name for p in app.graph.compile().order}


def camera_app(gpu, image, **settings):
    app = App(gpu).add_plugins(RenderCorePlugin(), PhysicalCameraPlugin(**settings))
    source = ImagePass(image)
    app.graph.add_pass(source)
    return app, app.plugins[-1], source


def test_histogram_and_meter_match_the_reference(gpu, ctx, rng):
    w, h = gpu.size
    image = hdr_image(rng, (h, w))
    app, camera, _ = camera_app(gpu, image, bloom=0.0, compensation=0.5)
    try:
        app.render()
        state = camera.read_state()
    finally:
        app.close()
    s = PhysicalCameraSettings(bloom=0.0, compensation=0.5)
    counts = ref.histogram(image.astype(np.float64), s.ev_range)
    assert counts.sum() == w * h
    mean = ref.metered_ev(counts, s.ev_range, s.metering_filter)
    target = ref.target_ev(mean, s.compensation, s.ev_range)
    # float32 sums of w·centre over 256 bins: ~1e-6 relative of EVs ~10
    assert state["target"] == pytest.approx(target, abs=1e-4)
    assert state["ev100"] == pytest.approx(target, abs=1e-4), "the first frame takes the metered EV at once"
    assert state["exposure"] == pytest.approx(float(ref.exposure_of(target)), rel=1e-5)
    assert state["primed"] == 1.0


def test_histogram_counts_exactly(gpu, ctx, rng):
    w, h = gpu.size
    image = hdr_image(rng, (h, w))
    app, _, _ = camera_app(gpu, image, bloom=0.0)
    probe = ProbePass(HISTOGRAM)
    app.graph.add_pass(probe)
    try:
        app.render()
        got = np.frombuffer(probe.data[HISTOGRAM][0], np.uint32).astype(np.int64)
    finally:
        app.close()
    assert np.array_equal(got, ref.histogram(image.astype(np.float64), PhysicalCameraSettings().ev_range))


@pytest.mark.parametrize("case", range(4))
def test_adaptation_follows_the_reference_over_frames(gpu, ctx, rng, case):
    """A scene that jumps brighter then darker: the EV100 frame by frame as adapt() says, never past
    the target, at most speed · dt per frame."""
    w, h = gpu.size
    speeds = dict(speed_up=float(rng.uniform(0.5, 6.0)), speed_down=float(rng.uniform(0.3, 3.0)),
                  transition=float(rng.uniform(0.2, 3.0)), compensation=float(rng.uniform(-1.0, 1.0)))
    levels = rng.uniform(0.01, 5.0, 3)
    app, camera, source = camera_app(gpu, np.ones((h, w, 4), np.float16), bloom=0.0, **speeds)
    s = camera.settings
    ev = None
    try:
        for level in levels:
            source.image = np.full((h, w, 4), level, np.float16)
            for _ in range(4):
                dt = float(rng.uniform(0.0, 0.1))
                app.update(dt)
                state = camera.read_state()
                counts = ref.histogram(source.image.astype(np.float64), s.ev_range)
                target = ref.target_ev(ref.metered_ev(counts, s.ev_range, s.metering_filter), s.compensation, s.ev_range)
                expected = target if ev is None else ref.adapt(ev, target, app.clock.dt, s.speed_up, s.speed_down,
                                                               s.transition)
                assert state["target"] == pytest.approx(target, abs=1e-4)
                assert state["ev100"] == pytest.approx(expected, abs=2e-4)
                if ev is not None:
                    assert abs(state["ev100"] - ev) <= max(s.speed_up, s.speed_down) * app.clock.dt + 2e-4
                    assert (state["ev100"] - target) * (ev - target) >= -1e-8, "never past the target"
                ev = state["ev100"]
    finally:
        app.close()


def test_manual_ev100_and_compensation_direction(gpu, ctx):
    w, h = gpu.size
    image = np.full((h, w, 4), 0.5, np.float16)
    app, camera, _ = camera_app(gpu, image, auto_exposure=False, ev100=2.5, bloom=0.0)
    try:
        app.render()
        assert camera.read_state()["exposure"] == pytest.approx(1.0 / (1.2 * 2 ** 2.5), rel=1e-6)
        shown = app.gpu.read_pixels().astype(np.float64)[..., :3]
        expected = present_levels(image[..., :3].astype(np.float64), 1.0 / (1.2 * 2 ** 2.5))[::-1]
        assert np.abs(shown - expected).max() <= 1
        means = []
        for compensation in (-1.0, 0.0, 1.0):
            camera.configure(auto_exposure=True, compensation=compensation)
            camera.reset()
            app.render()
            means.append(app.gpu.read_pixels()[..., :3].mean())
        assert means[0] < means[1] < means[2], "+1 EV of compensation gives a brighter image"
    finally:
        app.close()


@pytest.mark.parametrize("compensation", [0.0, 1.0])
def test_metered_frame_is_mid_grey(gpu, ctx, compensation):
    """Whatever the scene's level, a flat frame comes out at the same level once metered (2^c / 9.6
    before the tone map, c the compensation)."""
    w, h = gpu.size
    shown = []
    for level in (0.02, 1.0, 300.0):
        app, _, _ = camera_app(gpu, np.full((h, w, 4), level, np.float16), bloom=0.0, compensation=compensation)
        try:
            app.render()
            shown.append(app.gpu.read_pixels()[..., :3].astype(np.float64).mean())
        finally:
            app.close()
    expected = present_levels(np.full((4, 4, 3), 2.0 ** compensation / 9.6), dither=False).mean()
    # the bin's centre is at most half a bin (20/255 EV / 2) from the level: 2.7 % of exposure
    assert np.allclose(shown, expected, atol=1.5)


@pytest.mark.parametrize("levels", [1, 3, 6])
def test_bloom_chain_and_mix_match_the_reference(gpu, ctx, rng, levels):
    w, h = gpu.size
    image = np.concatenate([rng.uniform(0.0, 2.0, (h, w, 3)), np.ones((h, w, 1))], -1)
    image[rng.uniform(size=(h, w)) < 0.002, :3] = 5000.0         # a few suns
    image = image.astype(np.float16)
    weight = float(rng.uniform(0.01, 0.5))
    app, camera, _ = camera_app(gpu, image, auto_exposure=False, ev100=3.0, bloom=weight, bloom_levels=levels)
    probe = ProbePass(BLOOM)
    app.graph.add_pass(probe)
    try:
        app.render()
        data, (bw, bh) = probe.data[BLOOM]
        assert (bw, bh) == ((w + 1) // 2, (h + 1) // 2)
        got = np.frombuffer(data, np.float16).reshape(bh, bw, 4)[..., :3].astype(np.float64)
        shown = app.gpu.read_pixels().astype(np.float64)[::-1, :, :3]
    finally:
        app.close()
    expected = ref.bloom_chain(image.astype(np.float64), levels)
    # each level rounds to float16 (2^-11 relative), sums of <= 36 float32 products: a few half ulps per level
    assert np.abs(got - expected).max() <= 2.0 ** -10 * levels * np.abs(expected).max() + 1e-6
    mixed = ref.present_input(image.astype(np.float64), got, weight)         # the mix, of the GPU's own bloom
    levels_expected = present_levels(mixed, float(ref.exposure_of(3.0)))
    diff = np.abs(shown - levels_expected)
    assert diff.max() <= 1 and (diff == 0).mean() > 0.99


def test_bloom_keeps_a_flat_frame_and_its_energy(gpu, ctx):
    w, h = gpu.size
    flat = np.full((h, w, 4), 0.75, np.float16)
    assert np.allclose(ref.bloom_chain(flat.astype(np.float64), 5), 0.75)
    spot = np.zeros((64, 64, 3))
    spot[30:34, 30:34] = 1.0
    out = ref.up(ref.bloom_chain(spot, 4, half=False), (64, 64))
    assert out.sum() == pytest.approx(spot.sum(), rel=0.05), "a glow spreads light, it adds none"


def test_extremes_give_finite_frames(gpu, ctx):
    """Black, float16's largest and a NaN-free inf-free result for both; a one-pixel-tall frame."""
    w, h = gpu.size
    for value in (0.0, 65504.0):
        app, camera, _ = camera_app(gpu, np.full((h, w, 4), value, np.float16), bloom=0.5, bloom_levels=8)
        try:
            app.render()
            state = camera.read_state()
        finally:
            app.close()
        assert all(math.isfinite(v) for v in state.values())
        lo, hi = PhysicalCameraSettings().ev_range
        assert lo <= state["ev100"] <= hi


def test_disabled_runs_no_pass_and_uses_the_core_exposure(gpu, ctx):
    w, h = gpu.size
    image = np.full((h, w, 4), 0.3, np.float16)
    app, camera, _ = camera_app(gpu, image, enabled=False)
    try:
        app.render()
        assert not {"camera_exposure", "bloom"} & ran(app)
        shown = app.gpu.read_pixels().astype(np.float64)[..., :3]
        assert np.abs(shown - present_levels(image[..., :3].astype(np.float64))[::-1]).max() <= 1
        camera.configure(enabled=True, bloom=0.0)
        app.render()
        assert "camera_exposure" in ran(app) and "bloom" not in ran(app)
    finally:
        app.close()


@pytest.mark.parametrize("changes, words", [
    (dict(ev_range=(4.0, 4.0)), "ev_range must rise"),
    (dict(metering_filter=(0.9, 0.1)), "metering_filter"),
    (dict(metering_filter=(-0.1, 0.5)), "metering_filter"),
    (dict(bloom_levels=0), "bloom_levels"),
    (dict(speed_up=0.0), "speed_up"),
])
def test_bad_settings_are_named_and_change_nothing(changes, words):
    camera = PhysicalCameraPlugin()
    before = camera.settings
    with pytest.raises(ValueError, match=words):
        camera.configure(**changes)
    assert camera.settings is before
