"""The sprites splatted in compute (plugins/clouds/sprites/splat.py) against the point draw they replace:
the same image on and off screen, with the distance a fog reads, inside the volume and at full cover;
a list too short for a frame grows from what the frame needed; tiny targets and bad values."""
import numpy as np
import pytest

from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.sprites.plugin import CloudSpritePass
from atmos.plugins.clouds.sprites.splat import SpriteSplat
from atmos.plugins.fog import FogPlugin

from tests.test_cloud_render import ABOVE, BELOW, CENTER, frame, look, save, scene

# 8-bit tone-mapped pixels: one level of quantization either side, the 1/255 of light the splat leaves
# behind its opaque front and the point draw's float16 rounding at every blend make at most 2 levels
LEVELS = 2


def both(app, renderer, gpu, frames=1):
    """(points, compute) images of the same frozen frame; the compute one after ``frames`` frames."""
    renderer.configure(splat="points")
    points = frame(app, gpu)
    renderer.configure(splat="compute")
    for _ in range(frames):
        app.render()
    return points, gpu.read_pixels().astype(float)


def assert_same(points, splat, name):
    d = np.abs(points - splat).max(-1)
    if d.max() > LEVELS:
        save(np.concatenate([points, splat], 1), f"cloud_splat_{name}_mismatch.png")
    assert d.mean() < 0.4 and (d <= LEVELS).mean() > 0.999, (d.mean(), (d > LEVELS).mean(), d.max())


@pytest.mark.parametrize("view, downsample, fog", [("below", 1, False), ("above", 2, False), ("below", 2, True),
                                                   ("inside", 1, True)])
def test_the_splat_draws_the_points_image(gpu, ctx, view, downsample, fog, monkeypatch):
    # GL clips a point whose centre is off screen; the splat draws its part on screen (inside the layer
    # that is visible at the edges): to compare, it drops those sprites too
    monkeypatch.setattr(CloudSpritePass, "clip_centres", True)
    gpu.resize((320, 180))
    try:
        # a fog reads the clouds' own distance: the splat writes it
        app, renderer = scene(gpu, downsample=downsample, extra=[FogPlugin(density=0.002)] if fog else [])
        assert renderer.composition.distance is fog
        look(app, *{"below": BELOW, "above": ABOVE, "inside": (CENTER, (0.0, CENTER[1], 0.0))}[view])
        points, splat = both(app, renderer, gpu)
        stats = renderer.sprite_pass.splat
        assert stats.dropped == 0
        assert np.abs(points - frame_without(app, renderer, gpu)).max(-1).mean() > 2, "the clouds show"
        assert_same(points, splat, f"{view}_{downsample}")
        app.close()
    finally:
        gpu.resize((256, 144))


def test_sprites_centred_off_screen_still_draw_their_part(gpu, ctx):
    """Inside the layer: the point draw loses every sprite whose centre leaves the view (a pop at the
    edges); the splat keeps them: the two differ, most toward the edges."""
    app, renderer = scene(gpu, warmup=10, splat="compute")
    look(app, CENTER, (0.0, CENTER[1], 0.0))
    splat = frame(app, gpu)
    CloudSpritePass.clip_centres = True
    try:
        app.render()
        clipped = gpu.read_pixels().astype(float)
    finally:
        CloudSpritePass.clip_centres = False
    edge = np.zeros(splat.shape[:2], bool)
    edge[:8], edge[-8:], edge[:, :8], edge[:, -8:] = True, True, True, True
    d = np.abs(splat - clipped).max(-1)
    assert d[edge].mean() > 1.25 * d[~edge].mean() and d.mean() > 1.0, (d[edge].mean(), d[~edge].mean())
    app.close()


def frame_without(app, renderer, gpu):
    renderer.configure(enabled=False)
    app.render()
    img = gpu.read_pixels().astype(float)
    renderer.configure(enabled=True)
    return img


def test_long_tile_lists_sort_and_stop_at_an_opaque_front(gpu, ctx, monkeypatch):
    """Full cover seen from below through the whole layer: hundreds of sprites per tile to sort, most of
    them behind an opaque front; sorted in shared memory or in place, the same image."""
    monkeypatch.setattr(CloudSpritePass, "clip_centres", True)
    app, renderer = scene(gpu, cloud_density=1000, warmup=10, size_factor=6.0)
    look(app, (480.0, 60.0, 480.0), (480.0, 400.0, 470.0))
    points, splat = both(app, renderer, gpu)
    splat_state = renderer.sprite_pass.splat
    tiles = np.frombuffer(splat_state.tile_offset.read(), np.uint32)
    n = int(np.prod([-(-s // 16) for s in gpu.size]))
    assert np.diff(tiles[:n + 1].astype(np.int64)).max() > 256      # more than one entry per invocation to sort
    assert_same(points, splat, "full_cover")
    monkeypatch.setattr(CloudSpritePass, "shared_sort", 64)         # the lists sorted in place instead
    app.render()
    np.testing.assert_array_equal(gpu.read_pixels().astype(float), splat)
    app.close()


def test_a_list_too_short_grows_from_what_a_frame_needed(gpu, ctx, monkeypatch):
    monkeypatch.setattr(SpriteSplat, "first_entries", 0)     # the least list: 1,024 entries
    monkeypatch.setattr(CloudSpritePass, "clip_centres", True)
    app, renderer = scene(gpu, warmup=10, size_factor=6.0)
    look(app, *BELOW)
    points, short = both(app, renderer, gpu)
    splat = renderer.sprite_pass.splat
    assert np.abs(points - short).max() > 10, "entries past the list's end were dropped"
    for _ in range(3):                      # the need comes back without waiting, a frame or more late
        app.render()
    grown = gpu.read_pixels().astype(float)
    assert splat.needed > 1024 and splat.dropped >= 1
    assert splat.entries.size // 8 >= splat.needed
    assert_same(points, grown, "grown")
    app.close()


@pytest.mark.parametrize("size", [(1, 1), (0, 0), (333, 77)])
def test_tiny_and_odd_targets(gpu, ctx, size):
    app, renderer = scene(gpu, warmup=10, splat="compute", downsample=2)
    look(app, *BELOW)
    app.run_frames(1)
    gpu.resize(size)
    try:
        img = frame(app, gpu)
        assert img.shape[:2] == (max(1, size[1]), max(1, size[0])) and np.isfinite(img).all()
    finally:
        app.close()
        gpu.resize((256, 144))


def test_auto_splats_on_a_gpu_and_draws_points_on_a_software_renderer(gpu, ctx):
    renderer = CloudRenderPlugin()
    renderer.gpu = gpu
    assert renderer.splats() is (not gpu.software)
    assert CloudRenderPlugin(splat="compute").settings.splat == "compute"
    with pytest.raises(ValueError, match="CloudRenderSettings.splat"):
        CloudRenderPlugin(splat="tiles")


def test_the_tiles_hold_exactly_the_sprites_whose_squares_reach_them(gpu, ctx, monkeypatch):
    """The setup's records and the bin's lists against numpy: each sprite's pixel rectangle is the pixels
    whose centres lie inside its point square (clamped to the target), each tile's list holds exactly the
    sprites whose rectangles reach it, with their keys, and the keys are unique (the draw order is total)."""
    monkeypatch.setattr(SpriteSplat, "count", True)
    app, renderer = scene(gpu, warmup=10, splat="compute", downsample=1)
    look(app, *BELOW)
    frame(app, gpu)
    splat = renderer.sprite_pass.splat
    work = splat.work()
    n, needed = work["sprites"], work["entries"]
    raw = np.frombuffer(splat.records.read(), np.uint32)[:n * 40].reshape(n, 10, 4)
    head = raw[:, 0].view(np.float32)
    c, half = head[:, :2], head[:, 2:3]
    w, h = gpu.size
    lo = np.maximum(np.ceil(c - half - np.float32(0.5)), 0).astype(np.int64)
    hi = np.minimum(np.ceil(c + half - np.float32(0.5)) - 1, np.array([w - 1, h - 1])).astype(np.int64)
    rect = raw[:, 9].view(np.int32).astype(np.int64)
    np.testing.assert_array_equal(rect, np.concatenate([lo, hi], 1))
    assert (lo <= hi).all() and n > 100
    assert work["covered"] == int(np.prod(hi - lo + 1, axis=1).sum())      # what blended points would fill
    assert 0 < work["shaded"] <= work["covered"] and work["shaded"] <= work["tested"]
    keys = raw[:, 6, 3]
    assert len(np.unique(keys)) == n
    tiles_x, tiles_y = -(-w // 16), -(-h // 16)
    offsets = np.frombuffer(splat.tile_offset.read(), np.uint32)[:tiles_x * tiles_y + 1].astype(np.int64)
    entries = np.frombuffer(splat.entries.read(), np.uint32)[:2 * needed].reshape(-1, 2)
    assert offsets[-1] == needed and np.all(np.diff(offsets) >= 0)
    t0, t1 = rect[:, :2] // 16, rect[:, 2:] // 16
    for ty in range(tiles_y):
        for tx in range(tiles_x):
            tile = ty * tiles_x + tx
            want = np.flatnonzero((t0[:, 0] <= tx) & (tx <= t1[:, 0]) & (t0[:, 1] <= ty) & (ty <= t1[:, 1]))
            got = entries[offsets[tile]:offsets[tile + 1]]
            np.testing.assert_array_equal(np.sort(got[:, 1]), want)
            np.testing.assert_array_equal(got[:, 0], keys[got[:, 1]])
    app.close()


def test_closing_the_app_releases_every_splat_object(gpu, ctx):
    """The lists and the readback ring go with the pass, its fences deleted: nothing of the splat
    outlives the App (its programs belong to the context's cache)."""
    import moderngl
    app, renderer = scene(gpu, warmup=10, splat="compute")
    look(app, *BELOW)
    app.run_frames(4)
    splat = renderer.sprite_pass.splat
    owned = [splat.counters, splat.records, splat.tile_count, splat.tile_offset, splat.entries, *splat.ring]
    assert any(fence is not None for fence in splat.fences)
    app.close()
    assert all(isinstance(obj.mglo, moderngl.InvalidObject) for obj in owned)
    assert renderer.sprite_pass.splat is None and all(fence is None for fence in splat.fences)
