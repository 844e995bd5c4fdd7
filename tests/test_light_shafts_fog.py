"""The haze counted once: with a FogPlugin the marched shafts add no light of their own, they take
away the fog's in-scatter where the clouds shadow the air (plugins/light_shafts/march.py, SHAFT_FOG);
likewise the air's with the sky's aerial perspective (SHAFT_AERIAL), and both with both."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.fog import FogPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin
from atmos.plugins.light_shafts.plugin import LightShaftsPass
from atmos.plugins.sky_gradient import SkyGradientPlugin
from tests.test_light_shafts_march import BASE, CELL, SIZE, columns_volume


@pytest.fixture(scope="module")
def fog_gpu():
    gpu = create_headless(SIZE)
    yield gpu
    gpu.release()


@pytest.fixture(params=[None, (40, 24, 64)], ids=["march", "froxels"])
def froxels(request):
    """The shafts marched per texel, or from a froxel volume (LightShaftSettings.froxels)."""
    return request.param


def frame(gpu, density, shafts: bool, sky="fog", fog=True, color=(0.9, 0.9, 1.0), froxels=None, kept=None,
          sun=(0.0, 1.0, 0.25)) -> np.ndarray:
    """Linear colour of the gap view (test_light_shafts_march) under an exponential fog, with or without shafts
    (``kept``: a list given the passes the graph kept)."""
    extra = [LightShaftsPlugin(steps=48, max_distance=3000.0, froxels=froxels)] if shafts else []
    if fog:
        extra.append(FogPlugin(mode="exp", density=1.5e-3, sky=sky, fog_color=color))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
                               CloudsPlugin(CloudSettings(cell_size=CELL, base_altitude=BASE, shading=False,
                                                          sigma_t=0.05), density=density), *extra)
    app.insert_resource(Sun(np.array(sun, np.float64), (1.0, 0.95, 0.9)))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([320.0, 60.0, 20.0])
    cam.yaw, cam.pitch, cam.far = math.pi, 0.25, 5000.0
    try:
        app.render()
        assert gpu.ctx.error == "GL_NO_ERROR"
        if kept is not None:
            kept.extend(app.graph.compile().kept)
        return app.read_linear()[..., :3].astype(np.float64)
    finally:
        app.close()


def test_shafts_add_nothing_to_the_fog_where_nothing_shadows_the_air(fog_gpu, froxels):
    empty = np.zeros((32, 4, 32), np.float32)
    alone, both = frame(fog_gpu, empty, False, froxels=froxels), frame(fog_gpu, empty, True, froxels=froxels)
    assert np.abs(both - alone).max() < 2e-3 * max(alone.max(), 1.0), "the fog's in-scatter is not counted twice"
    kept = frame(fog_gpu, columns_volume(), True, sky="keep", froxels=froxels)
    assert np.isfinite(kept).all()


def test_cloud_shadows_show_as_darker_rays_in_the_fog(fog_gpu, froxels):
    volume = columns_volume()
    alone, both = frame(fog_gpu, volume, False, froxels=froxels), frame(fog_gpu, volume, True, froxels=froxels)
    attenuated = frame(fog_gpu, volume, False, color=(0.0, 0.0, 0.0))     # f · scene: the fog without its light
    dark = (alone - both).mean(-1)                     # what the shafts took away
    assert np.isfinite(both).all() and dark.min() > -2e-3, "the shafts only take light away"
    lost = dark.mean(axis=0)                           # per image column
    w = lost.size
    centre = lost[int(0.45 * w):int(0.55 * w)].mean()
    sides = np.concatenate([lost[int(0.02 * w):int(0.2 * w)], lost[int(0.8 * w):int(0.98 * w)]]).mean()
    assert sides > 0.02 and sides > 3.0 * centre, f"shadowed air darker ({sides:.3f}) than the lit gap ({centre:.3f})"
    inscatter = (alone - attenuated).mean(-1)          # (1 − f) C_fog: never more is taken away
    assert (dark <= inscatter + 4e-3).all()


def test_under_a_kept_sky_the_rays_show_against_the_sky(fog_gpu, froxels):
    """sky="keep": the fog leaves the sky as drawn (it holds the air's haze itself); the shafts take the
    fog's sunlit in-scatter out of it where the clouds shadow the first max_distance of the ray, so the
    lit gap shows as a ray against a darker sky, never below black and never more than the fog's share."""
    volume = columns_volume()
    bare = frame(fog_gpu, volume, False, fog=False, froxels=froxels)
    alone = frame(fog_gpu, volume, False, sky="keep", froxels=froxels)
    both = frame(fog_gpu, volume, True, sky="keep", froxels=froxels)
    sky = np.all(bare == alone, -1)                    # the pixels the kept fog leaves alone
    assert sky.mean() > 0.3
    dark = (alone - both).mean(-1)
    assert np.isfinite(both).all() and both.min() >= 0.0 and dark.min() > -2e-3, "only light taken away"
    share = 0.8 * np.array([0.9, 0.9, 1.0]) * (1.0 - math.exp(-1.5e-3 * 3000.0))     # fog_sun_share C (1 − f)
    assert ((alone - both)[sky] <= share + 4e-3).all()
    lost = np.where(sky, dark, np.nan)[sky.any(1)]
    lost = np.nanmean(lost, axis=0)                    # per image column, sky rows only
    w = lost.size
    centre = lost[int(0.47 * w):int(0.53 * w)].mean()
    sides = np.concatenate([lost[int(0.02 * w):int(0.2 * w)], lost[int(0.8 * w):int(0.98 * w)]]).mean()
    assert sides > 0.1 and sides > 5.0 * centre, f"the sky behind shadowed air darker ({sides:.3f}) than the ray ({centre:.3f})"


def aerial_frame(gpu, density, shafts: bool, aerial: bool = True, fog_color=None, froxels=None,
                 sun=(0.0, 1.0, 0.25), aerial_froxels=(32, 32, 64)) -> np.ndarray:
    """The gap view under the physical sky, its aerial perspective on (or off), with or without shafts;
    ``fog_color``: under an exponential fog of that colour too (mixed with the air along the ray,
    atmos.composition)."""
    from atmos.plugins.sky import SkyPlugin
    extra = [LightShaftsPlugin(steps=48, max_distance=3000.0, froxels=froxels)] if shafts else []
    if fog_color is not None:
        extra.append(FogPlugin(mode="exp", density=1.5e-3, sky="keep", fog_color=fog_color))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin(model="physical", stars=False,
                                                                         aerial_perspective=aerial,
                                                                         aerial_froxels=aerial_froxels), GroundPlugin(),
                               CloudsPlugin(CloudSettings(cell_size=CELL, base_altitude=BASE, shading=False,
                                                          sigma_t=0.05), density=density), *extra)
    app.insert_resource(Sun(np.array(sun, np.float64)))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([320.0, 60.0, 20.0])
    cam.yaw, cam.pitch, cam.far = math.pi, 0.25, 5000.0
    try:
        app.run_frames(1)
        kept = app.graph.compile().kept
        fused = shafts and froxels is not None and LightShaftsPass.fuse_media   # the apply composites the media
        assert ("aerial_perspective" in kept) == (aerial and not fused) and ("light_shafts" in kept) == shafts
        assert ("fog" in kept) == (fog_color is not None and not fused)
        media = app.graph.compile().resources
        assert "media_clear" not in kept and ("media_light" in media) == (aerial and fog_color is not None
                                                                          and not fused), \
            "the media targets with the fog and the air in their own passes, made by the fog (the only local medium)"
        return app.read_linear()[..., :3].astype(np.float64)
    finally:
        app.close()


def test_with_the_skys_aerial_perspective_shafts_only_take_its_light_away_in_cloud_shadow(fog_gpu, froxels):
    """SHAFT_AERIAL: no fog, the physical sky's aerial perspective owns the air's light; the shafts add
    none of their own (nothing changes without clouds) and take away only what the clouds shadow,
    never more than the aerial perspective put in."""
    empty = np.zeros((32, 4, 32), np.float32)
    alone, both = aerial_frame(fog_gpu, empty, False, froxels=froxels), aerial_frame(fog_gpu, empty, True, froxels=froxels)
    assert np.abs(both - alone).max() < 2e-3 * max(alone.max(), 1.0), "the air's in-scatter is not counted twice"
    volume = columns_volume()
    alone, both = aerial_frame(fog_gpu, volume, False, froxels=froxels), aerial_frame(fog_gpu, volume, True, froxels=froxels)
    plain = aerial_frame(fog_gpu, volume, False, aerial=False, froxels=froxels)
    dark = (alone - both).mean(-1)
    lost = dark.mean(axis=0)
    w = lost.size
    centre = lost[int(0.45 * w):int(0.55 * w)].mean()
    sides = np.concatenate([lost[int(0.02 * w):int(0.2 * w)], lost[int(0.8 * w):int(0.98 * w)]]).mean()
    assert np.isfinite(both).all() and dark.min() > -2e-3, "the shafts only take light away"
    assert sides > 3.0 * centre and sides > 2e-3, (sides, centre)
    put_in = (alone - plain).mean(-1)               # the aerial perspective's light on the scene (the sky holds
    scene = put_in > 1e-4                           # its own: there the shafts take from the sky view's air)
    assert scene.mean() > 0.2 and (dark[scene] <= put_in[scene] + 2e-3).all(), "never more than it put in"


def both_frame(gpu, density, shafts: bool, light: bool = True, froxels=None) -> np.ndarray:
    """:func:`aerial_frame` under the fog too; ``light`` False: the fog's colour black."""
    return aerial_frame(gpu, density, shafts, fog_color=(0.9, 0.9, 1.0) if light else (0.0, 0.0, 0.0),
                        froxels=froxels)


def test_with_fog_and_air_both_the_shafts_take_away_both_in_cloud_shadow_only(fog_gpu, froxels):
    """SHAFT_FOG and SHAFT_AERIAL together (the fog under the air, mixed): nothing changes without
    clouds; with them the shafts only take light away, more in the shadowed air than in the lit gap, and
    the air's in-scatter is shadowed too (seen alone with the fog's colour black)."""
    empty = np.zeros((32, 4, 32), np.float32)
    alone, both = both_frame(fog_gpu, empty, False, froxels=froxels), both_frame(fog_gpu, empty, True, froxels=froxels)
    assert np.abs(both - alone).max() < 2e-3 * max(alone.max(), 1.0), "nothing shadows the air: nothing taken"
    volume = columns_volume()
    alone, both = both_frame(fog_gpu, volume, False, froxels=froxels), both_frame(fog_gpu, volume, True, froxels=froxels)
    dark = (alone - both).mean(-1)
    assert np.isfinite(both).all() and dark.min() > -2e-3, "the shafts only take light away"
    lost = dark.mean(axis=0)
    w = lost.size
    centre = lost[int(0.45 * w):int(0.55 * w)].mean()
    sides = np.concatenate([lost[int(0.02 * w):int(0.2 * w)], lost[int(0.8 * w):int(0.98 * w)]]).mean()
    assert sides > 3.0 * centre and sides > 2e-3, (sides, centre)
    # the fog's light black: what is taken away then is the air's in-scatter in the clouds' shadow (seen:
    # 4.1e-3 beside the gap, 4e-4 in it; the fog's and the air's together 8.2e-2 and 4.6e-3)
    air = (both_frame(fog_gpu, volume, False, light=False, froxels=froxels) - both_frame(fog_gpu, volume, True, light=False, froxels=froxels)).mean(-1)
    air_lost = air.mean(axis=0)
    air_sides = np.concatenate([air_lost[int(0.02 * w):int(0.2 * w)], air_lost[int(0.8 * w):int(0.98 * w)]]).mean()
    assert air.min() > -2e-3 and air_sides > 1e-3 and air_sides > 3.0 * air_lost[int(0.45 * w):int(0.55 * w)].mean(), \
        "the air's in-scatter is shadowed too"


def test_a_heterogeneous_fog_keeps_the_per_texel_march_and_the_froxels_switch_live(fog_gpu):
    """The froxel volume holds sums that a heterogeneous fog (its turbulence taken at each pixel's end) cannot
    share between pixels: with one the shafts march per texel; a homogeneous fog, or froxels set or unset
    live, switch on the next frame."""
    shafts, fog = LightShaftsPlugin(max_distance=3000.0), FogPlugin(mode="hetero_exp", density=1.5e-3)
    app = App(fog_gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
                                   CloudsPlugin(CloudSettings(cell_size=CELL, base_altitude=BASE, shading=False,
                                                              sigma_t=0.05), density=columns_volume()), shafts, fog)
    app.insert_resource(Sun(np.array([0.0, 1.0, 0.25])))
    app.startup()
    cam = app.resource(Camera)
    cam.position, cam.yaw, cam.pitch, cam.far = np.array([320.0, 60.0, 20.0]), math.pi, 0.25, 5000.0

    def targets():
        app.render()
        assert fog_gpu.ctx.error == "GL_NO_ERROR" and np.isfinite(app.read_linear()).all()
        dump = app.graph.dump()
        return "light_shafts_march " in dump, "light_shafts_volume " in dump
    try:
        assert targets() == (True, False)
        fog.configure(mode="exp")
        assert targets() == (False, True)
        shafts.configure(froxels=None)
        assert targets() == (True, False)
        shafts.configure(froxels=(16, 9, 8))
        assert targets() == (False, True)
    finally:
        app.close()


@pytest.mark.parametrize("sky", ["fog", "keep"])
@pytest.mark.parametrize("sun", [(0.0, 1.0, 0.25), (0.0, -0.2, 1.0)], ids=["day", "sun_down"])
def test_the_froxels_apply_composites_the_fog_as_the_fogs_own_pass_did(fog_gpu, monkeypatch, sky, sun):
    """The fog the only local medium: the shafts' froxel apply composites it (exactly, per pixel) and takes
    the shadowed share away in one write, the fog's pass culled; with the sun down the fog alone. The frame
    equals the fog's pass then the apply, up to the float16 rounding of the colour between them."""
    volume, kept, apart_kept = columns_volume(), [], []
    fused = frame(fog_gpu, volume, True, sky=sky, froxels=(40, 24, 64), kept=kept, sun=sun)
    monkeypatch.setattr(LightShaftsPass, "fuse_media", False)
    apart = frame(fog_gpu, volume, True, sky=sky, froxels=(40, 24, 64), kept=apart_kept, sun=sun)
    assert "fog" not in kept and "light_shafts" in kept and "fog" in apart_kept
    assert np.isfinite(fused).all() and fused.min() >= 0.0
    step = 2.0 ** -10 * (np.abs(apart) + np.abs(fused)) + 1e-6      # float16's step, rounding toward zero
    assert (np.abs(fused - apart) <= 2.0 * step).all(), np.abs(fused - apart).max()
    fog_alone = frame(fog_gpu, volume, False, sky=sky, sun=sun)
    if sun[1] < 0.0:                                   # no sunlit haze: the fog alone, as its own pass draws it
        assert (np.abs(fused - fog_alone) <= 2.0 * step).all()
    else:
        assert (fog_alone - fused).mean() > 1e-3, "the shafts still take the shadowed share away"



def test_the_fog_moves_between_its_pass_and_the_shafts_apply_live(fog_gpu):
    """Live changes that decide who composites the fog (the shafts' froxels on and off, their mode, a
    heterogeneous fog) move it on the next frame, each frame fogged once: as a fresh App with those settings."""
    shafts = LightShaftsPlugin(max_distance=3000.0, froxels=(40, 24, 64))
    fog = FogPlugin(mode="exp", density=1.5e-3)
    app = App(fog_gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), shafts, fog)
    app.insert_resource(Sun(np.array([0.0, 0.4, 1.0])))
    app.startup()
    app.resource(Camera).position = np.array([0.0, 30.0, 0.0])
    try:
        for changes, fused in ((dict(), True), (dict(froxels=None), False), (dict(froxels=(40, 24, 64)), True),
                               (dict(mode="screen"), False), (dict(mode="march"), True)):
            shafts.configure(**changes)
            app.render()
            kept = app.graph.compile().kept
            assert ("fog" not in kept) == fused and "light_shafts" in kept, changes
            assert gpu_ok(app)
        fog.configure(mode="hetero_exp")
        app.render()
        assert "fog" in app.graph.compile().kept and gpu_ok(app)
    finally:
        app.close()


def gpu_ok(app) -> bool:
    """No GL error and a finite frame."""
    return app.gpu.ctx.error == "GL_NO_ERROR" and bool(np.isfinite(app.read_linear()).all())


@pytest.mark.parametrize("fog_color", [None, (1.0, 0.9, 0.8)], ids=["air", "fog_and_air"])
@pytest.mark.parametrize("sun, aerial_froxels", [((0.0, 1.0, 0.25), (32, 32, 64)), ((0.0, 1.0, 0.25), None),
                                                 ((0.0, -0.05, 1.0), (32, 32, 64))],
                         ids=["froxel_air", "marched_air", "sun_down"])
def test_the_froxels_apply_composites_the_air_and_the_fog_as_their_passes_did(fog_gpu, monkeypatch, fog_color, sun,
                                                                               aerial_froxels):
    """The sky's aerial perspective on (and a fog, mixed with it along the ray): the shafts' froxel apply
    composites both and takes the shadowed share away in one write, the fog's and the sky's passes and
    the media targets gone (aerial_frame checks); the frame equals those passes then the apply, up to the
    float16 rounding of the colour between them."""
    volume = columns_volume()
    fused = aerial_frame(fog_gpu, volume, True, fog_color=fog_color, froxels=(40, 24, 64), sun=sun,
                         aerial_froxels=aerial_froxels)
    monkeypatch.setattr(LightShaftsPass, "fuse_media", False)
    apart = aerial_frame(fog_gpu, volume, True, fog_color=fog_color, froxels=(40, 24, 64), sun=sun,
                         aerial_froxels=aerial_froxels)
    assert np.isfinite(fused).all() and min(fused.min(), apart.min()) >= 0.0 and fused.max() > 0.0
    step = 2.0 ** -10 * (np.abs(apart) + np.abs(fused)) + 1e-6      # float16's step, rounding toward zero
    assert (np.abs(fused - apart) <= 3.0 * step).all(), np.abs(fused - apart).max()
