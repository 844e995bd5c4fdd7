"""The physical sky (SkySettings.model = "physical", Hillaire 2020): the float64 reference on analytic
cases, the GPU LUTs and pass against it, the Sun's light from the same model, settings, culling and
composition with the fog and the clouds."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera, view_basis
from atmos.defaults import DefaultPlugins
from atmos.lighting import Sun
from atmos.plugins.daylight import DaylightPlugin
from atmos.plugins.fog import FogPlugin
from atmos.plugins.sky.light import horizon_directions
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky import AtmosphereSettings, SkyPlugin, SkySettings, physical_sky_color
from atmos.plugins.sky import atmosphere as ref
from atmos.plugins.sky import sun_light
from atmos.plugins.sky.luts import AtmosphereLuts
from atmos.composition import MEDIA_LIGHT, MEDIA_TRANSMITTANCE, Composition, media_mix
from atmos.graph import RenderPass

THIN = 1e-5     # coefficients × this: the optically thin limit


def rayleigh_only(scale=1.0, **fields) -> AtmosphereSettings:
    base = AtmosphereSettings()
    values = dict(rayleigh_scattering=tuple(scale * c for c in base.rayleigh_scattering),
                  mie_scattering=(0.0,) * 3, mie_absorption=(0.0,) * 3, ozone_absorption=(0.0,) * 3)
    return AtmosphereSettings(**{**values, **fields})


def sun_at(elevation_deg, azimuth_deg=0.0) -> np.ndarray:
    return Sun.from_angles(elevation_deg, azimuth_deg).direction


# -- the reference on analytic cases ------------------------------------------------------------------

def test_zenith_transmittance_of_exponential_and_tent_profiles_is_analytic():
    s = rayleigh_only(mie_scattering=(2e-6,) * 3, mie_absorption=(1e-6,) * 3, ozone_absorption=(1e-6, 2e-6, 3e-6))
    m = ref.medium(s)
    top = s.atmosphere_height
    want = (m["ray"] * s.rayleigh_scale_height * (1 - math.exp(-top / s.rayleigh_scale_height))
            + m["mie_t"] * s.mie_scale_height * (1 - math.exp(-top / s.mie_scale_height))
            + m["ozone"] * 0.5 * s.ozone_width)                       # the tent's area
    exact = ref.optical_depth(m, m["rg"], 1.0, top, 4000)
    assert np.allclose(exact, want, rtol=1e-5)
    lut = ref.transmittance_lut(s)                                    # 40 steps, read at (ground, zenith)
    u, v = ref.transmittance_uv(m, m["rg"], 1.0)
    assert np.allclose(np.exp(-ref.bilinear(lut, u, v)), np.exp(-want), rtol=2e-3)
    # a horizontal ray from the ground: the LUT's edge texel is the longest path it holds
    assert (ref.transmittance_to_sun(m, lut, m["rg"] + 1.0, 0.0) < np.exp(-want) ** 20).all()


def test_single_scattering_in_the_thin_limit_is_the_column_times_the_phase():
    s = rayleigh_only(THIN, multiple_scattering=0.0, ground_albedo=(0.0,) * 3)
    m = ref.medium(s)
    h, top = s.rayleigh_scale_height, s.atmosphere_height
    for elevation in (80.0, 30.0, 5.0):
        sun = sun_at(elevation)
        nu = sun[1]                                                   # looking straight up
        want = m["sun"] * m["ray"] * h * (1 - math.exp(-top / h)) * ref.rayleigh_phase(nu)
        got = ref.sky_radiance(np.array([[0.0, 1.0, 0.0]]), sun, 0.0, s, steps=64)[0]
        assert np.allclose(got, want, rtol=1e-3), elevation


def test_without_absorption_scattered_and_escaping_light_add_up_to_one():
    """Energy: in a purely scattering atmosphere with no ground, every photon along a ray is either
    scattered (the transfer ∫σs T dt) or gets through (T) — exactly, step by step."""
    s = rayleigh_only(30.0, mie_scattering=(2e-5,) * 3, ground_albedo=(0.0,) * 3)
    m = ref.medium(s)
    tlut = ref.transmittance_lut(s)
    mu = np.linspace(-1, 1, 41)
    r = np.full(mu.shape, m["rg"] + 3000.0)
    _, transfer = ref.integrate(m, tlut, r, mu, 0.3, 0.1, 24, isotropic=True)
    ground = ref.hits_ground(m["rg"], r, mu)
    t = np.where(ground, ref.distance_to_ground(m["rg"], r, mu), ref.distance_to_top(m["rt"], r, mu))
    escaping = np.exp(-sum(ref.coefficients(m, np.sqrt(r**2 + tm**2 + 2 * r * mu * tm))[2] * dt[..., None]
                           for tm, dt in segments(t, 24)))
    assert np.allclose(transfer + escaping, 1.0, atol=1e-12)
    # and the multiple-scattering sum is the geometric series of that transfer: Ψ = L2 / (1 − f)
    ms = ref.multiscattering_lut(s, tlut, size=4)
    assert np.isfinite(ms).all() and (ms >= 0).all()


def segments(t, steps):
    for i in range(steps):
        t0, t1 = t * (i / steps) ** 2, t * ((i + 1) / steps) ** 2
        yield 0.5 * (t0 + t1), t1 - t0


def test_lut_mappings_invert():
    m = ref.medium(AtmosphereSettings())
    u, v = np.meshgrid(ref.texel_centres(64), ref.texel_centres(16))
    r, mu = ref.transmittance_params(m, u, v)
    u2, v2 = ref.transmittance_uv(m, r, mu)
    assert np.allclose(u2, u, atol=1e-7) and np.allclose(v2, v, atol=1e-7)
    for altitude in (0.0, 1500.0, 20000.0):
        rr = ref.camera_radius(m, altitude)
        mu, cos_az = ref.sky_view_params(m, rr, u, v)
        u3, v3 = ref.sky_view_uv(m, rr, mu, cos_az)
        assert np.allclose(u3, u, atol=1e-7) and np.allclose(v3, v, atol=1e-6)


# -- the GPU against the reference ----------------------------------------------------------------------

def test_thin_segments_of_a_twilight_sky_are_not_brightened_by_float_cancellation(gpu, ctx):
    """A segment high up (optical depth ~1e-9) spreads its source over ∫ e^(−σt s) ds ≈ dt; the float
    quotient (1 − e^(−x)) / σt made that up to 1e3 dt: Ψms 2 % and the twilight sky up to 9 % off
    (lib/exp_mean.glsl). Now both within 4e-4 of the reference, to a floor of 1e-6 of their max."""
    luts = AtmosphereLuts(gpu)
    try:
        s = AtmosphereSettings()
        luts.update(s, 5000.0, -0.3)
        tlut = ref.transmittance_lut(s)
        mslut = ref.multiscattering_lut(s, tlut)
        for name, want in (("multiscattering", mslut), ("sky_view", ref.sky_view_lut(s, tlut, mslut, 5000.0, -0.3))):
            relative = np.abs(luts.read(name) - want) / (np.abs(want) + 1e-6 * want.max())
            assert relative.max() <= 2e-3, (name, relative.max())
    finally:
        luts.release()


def random_atmosphere(rng) -> AtmosphereSettings:
    b = AtmosphereSettings()
    k = lambda: rng.uniform(0.3, 3.0)     # noqa: E731
    return AtmosphereSettings(rayleigh_scattering=tuple(k() * c for c in b.rayleigh_scattering),
                              mie_scattering=(k() * 4e-6,) * 3, mie_absorption=tuple(rng.uniform(0, 1e-6, 3)),
                              ozone_absorption=tuple(k() * c for c in b.ozone_absorption),
                              rayleigh_scale_height=rng.uniform(5000, 12000), mie_scale_height=rng.uniform(500, 3000),
                              mie_g=rng.uniform(0.5, 0.9), ground_albedo=tuple(rng.uniform(0, 1, 3)),
                              atmosphere_height=rng.uniform(60e3, 120e3), multiple_scattering=rng.uniform(0, 1))


def test_gpu_luts_match_the_float64_reference_on_random_atmospheres(gpu, ctx, rng):
    luts = AtmosphereLuts(gpu)
    try:
        for _ in range(2):
            s = random_atmosphere(rng)
            altitude, sun_y = rng.uniform(0, 20000), rng.uniform(-0.3, 1.0)
            luts.update(s, altitude, sun_y)
            tlut = ref.transmittance_lut(s)
            mslut = ref.multiscattering_lut(s, tlut)
            sv = ref.sky_view_lut(s, tlut, mslut, altitude, sun_y)
            for name, want, atol in (("transmittance", tlut, 1e-4), ("multiscattering", mslut, 1e-4 * mslut.max()),
                                     ("sky_view", sv, 1e-3 * sv.max())):
                # (float32 at a grazing sun and deep in twilight: at most 2.4e-4 of the max over 40 seeds)
                got = luts.read(name)
                assert np.isfinite(got).all(), name
                err = np.abs(got - want) - 2e-3 * np.abs(want)
                assert err.max() <= atol, (name, s, altitude, sun_y, np.abs(got - want).max())
    finally:
        luts.release()


def physical_app(gpu, *plugins, sun=None, altitude=2.0, **sky):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin(model="physical", **sky), *plugins)
    if sun is not None:
        app.insert_resource(Sun(direction=sun))
    app.startup()
    app.resource(Camera).position = np.array([0.0, altitude, 0.0])
    return app


def test_the_physical_sky_pass_matches_the_reference_in_every_pixel(gpu, ctx, rng):
    size = (48, 32)
    for altitude, elevation in ((2.0, rng.uniform(1, 15)), (rng.uniform(500, 20000), rng.uniform(-5, 60))):
        sun = sun_at(elevation, rng.uniform(0, 360))
        app = physical_app(gpu, sun=sun, altitude=altitude, stars=False)
        cam = app.resource(Camera)
        cam.yaw, cam.pitch = math.atan2(sun[0], -sun[2]) + rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.6)
        gpu.resize(size)
        got = app.read_linear()[::-1, :, :3]                        # row 0 at the bottom, as pixel_dirs
        sky = next(p for p in app.plugins if isinstance(p, SkyPlugin))
        x, y = np.meshgrid((np.arange(size[0]) + 0.5) / size[0] * 2 - 1, (np.arange(size[1]) + 0.5) / size[1] * 2 - 1)
        dirs = np.stack([x, y, np.ones_like(x)], -1) @ view_basis(cam, size[0] / size[1]).T
        dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
        s = app.resource(Sun)
        want = physical_sky_color(dirs, s.direction, s.color, sky.luts.read("sky_view").astype(np.float64), altitude,
                                  sky.settings, pixel_angle=cam.fov_y / size[1])
        assert np.isfinite(got).all()
        # at the horizon the latitude mapping's square root is singular: float32 moves the LUT row
        # there by a fraction of a texel (ground to sky): those rows are left out
        m = ref.medium(sky.settings.atmosphere)
        mu, cos_az, _, _ = ref.view_angles(dirs, s.direction)
        _, v = ref.sky_view_uv(m, ref.camera_radius(m, altitude), mu, cos_az)
        ok = np.abs(v - 0.5) > 1.5 / ref.SKY_VIEW_SIZE[1]
        assert ok.mean() > 0.7
        err = np.abs(got - want)[ok]
        assert (err <= 2e-3 * np.abs(want[ok]) + 2e-4 * want.max()).all(), err.max()
        # and the LUT read in the pass is the directly ray-marched sky within its resolution
        direct = ref.sky_radiance(dirs, s.direction, altitude, sky.settings.atmosphere)
        sampled = ref.sample_sky_view(sky.settings.atmosphere, sky.luts.read("sky_view").astype(np.float64),
                                      altitude, dirs, s.direction)
        above = dirs[..., 1] > 0.02
        assert np.median(np.abs(sampled - direct)[above] / direct[above]) < 0.01
        app.close()
    gpu.resize((256, 144))


def ground_frames(gpu, size, altitude, sun, yaw, pitch, **sky):
    """read_linear (row 0 at the bottom) of a physical sky over the ground plane, aerial perspective off
    and on, the view rays (a function of a sub-pixel offset), and the app (open)."""
    app = physical_app(gpu, GroundPlugin(half_size=5e5), sun=sun, altitude=altitude, stars=False, **sky)
    cam = app.resource(Camera)
    cam.yaw, cam.pitch, cam.near, cam.far = yaw, pitch, 1.0, 1e6
    gpu.resize(size)
    plugin = next(p for p in app.plugins if isinstance(p, SkyPlugin))
    plain = app.read_linear()[::-1].astype(np.float64)
    plugin.configure(aerial_perspective=True)
    hazed = app.read_linear()[::-1].astype(np.float64)
    def rays(dx=0.0, dy=0.0):
        """The view rays through the pixel centres, moved by (dx, dy) pixels."""
        x, y = np.meshgrid((np.arange(size[0]) + 0.5 + dx) / size[0] * 2 - 1,
                           (np.arange(size[1]) + 0.5 + dy) / size[1] * 2 - 1)
        return np.stack([x, y, np.ones_like(x)], -1) @ view_basis(cam, size[0] / size[1]).T
    return plain, hazed, rays, app


class MediaReadback(RenderPass):
    """Reads "media_light" and "media_transmittance" back (GL row order) while they exist."""
    name = "media_readback"
    phase = "readback"
    value = None

    def __init__(self, comp):
        self.comp = comp

    def setup(self, builder):
        if self.comp.media:
            builder.read(MEDIA_LIGHT)
            builder.read(MEDIA_TRANSMITTANCE)
            builder.side_effect()

    def execute(self, frame):
        w, h = frame.gpu.size
        light = np.frombuffer(frame.resource(MEDIA_LIGHT).read(), np.float32).reshape(h, w, 4)[..., :3]
        self.value = light.astype(np.float64), np.frombuffer(frame.resource(MEDIA_TRANSMITTANCE).read(),
                                                             np.float32).reshape(h, w).astype(np.float64)


@pytest.mark.parametrize("medium", ["fog", "volumetric_fog"])
def test_local_media_and_the_air_mix_along_the_ray_instead_of_adding_twice(gpu, ctx, rng, medium):
    """A FogPlugin (or a VolumetricFogPlugin) and the aerial perspective together: the air is mixed with
    the local medium along each ray (atmos.composition media_mix) over the ground plane, against the
    float64 composite of the medium's own (light, transmittance) (read back from the media targets; for
    the exp fog also checked against its analytic value at the pixel's distance) and the air's (the float64
    march on the GPU's LUTs). A medium of density 0 leaves the air as it was; an opaque one hides the air
    (the old composite, the medium then the air over it, is far off: the test can fail). The media
    targets exist only with both."""
    from atmos.plugins.volumetric_fog import VolumetricFogPlugin
    size, altitude = (48, 32), float(rng.uniform(20.0, 200.0))
    sun = sun_at(rng.uniform(3, 30), rng.uniform(0, 360))
    if medium == "fog":
        local = FogPlugin(mode="exp", density=0.0, sky="keep", fog_color=(0.7, 0.55, 0.4))
        thin, thick = dict(density=float(rng.uniform(5e-4, 1.5e-3))), dict(density=0.05)
        none = dict(density=0.0)
    else:
        local = VolumetricFogPlugin(center=(0.0, altitude, 0.0), falloff=0.0, bias=0.5, absorption=0.0,
                                    max_distance=3000.0, animate=False, steps=64)
        thin, thick, none = dict(absorption=float(rng.uniform(5e-4, 1.5e-3))), dict(absorption=0.2), dict(absorption=0.0)
    app = physical_app(gpu, GroundPlugin(half_size=5e5), local, sun=sun, altitude=altitude, stars=False,
                       aerial_froxels=None)
    readback = app.graph.add_pass(MediaReadback(app.resource(Composition)))
    cam = app.resource(Camera)
    cam.yaw, cam.pitch, cam.near, cam.far = math.atan2(sun[0], -sun[2]) + rng.uniform(-1, 1), -0.25, 1.0, 1e6
    gpu.resize(size)
    sky = next(p for p in app.plugins if isinstance(p, SkyPlugin))

    def frame(changes, air):
        local.configure(**changes)
        sky.configure(aerial_perspective=air)
        resources = app.graph.compile().resources
        assert (MEDIA_LIGHT in resources and MEDIA_TRANSMITTANCE in resources) == air, "the media targets only with both"
        return app.read_linear()[::-1, :, :3].astype(np.float64)

    bare, air_alone = frame(none, False), frame(none, True)
    x, y = np.meshgrid((np.arange(size[0]) + 0.5) / size[0] * 2 - 1, (np.arange(size[1]) + 0.5) / size[1] * 2 - 1)
    dirs = np.stack([x, y, np.ones_like(x)], -1) @ view_basis(cam, size[0] / size[1]).T
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    distance = altitude / np.maximum(-dirs[..., 1], 1e-6)
    close = (dirs[..., 1] < -0.01) & (distance < 2e4)
    assert close.mean() > 0.3
    tlut, mslut = (sky.luts.read(name).astype(np.float64) for name in ("transmittance", "multiscattering"))
    light, trans = ref.aerial_perspective(sky.settings.atmosphere, tlut, mslut, altitude, dirs, sun, distance,
                                          sky.settings.aerial_steps)
    t_air = trans.mean(-1)
    for changes in (thin, thick):
        alone, both = frame(changes, False), frame(changes, True)
        local_light, t_local = readback.value
        if medium == "fog":
            tau = changes["density"] * distance                 # the fog's optical depth at the pixel's distance
            exact = close & (tau < 20.0)
            off = np.abs(-np.log(np.maximum(t_local, 1e-30)) - tau) / (tau + 0.05)
            # against the flat plane's distance: up to 3.2 % off the ground drawn, 3-6 km away, seen
            assert off[exact].max() < 0.05, (off[exact].max(), distance[exact][off[exact].argmax()])
            assert np.abs(local_light - (1.0 - t_local)[..., None] * np.asarray(local.settings.fog_color))[close].max() < 2e-3
        assert np.abs(alone - (bare * t_local[..., None] + local_light))[close].max() < 4e-3 * max(1.0, alone.max())
        want = bare * (t_local * t_air)[..., None] + media_mix(light, t_air, local_light, t_local)
        assert (t_local[close] < 0.95).mean() > 0.3, "the medium must show"
        rmse = np.sqrt(((both - want)[close] ** 2).sum() / (want[close] ** 2).sum())
        assert rmse < 5e-3, rmse          # seen: 7e-4 to 3.1e-3 (float16 colour; both media alike)
        if changes is thick:
            # where the medium is opaque (tau > 4) the air keeps its share tau_air / (tau_air + tau) of the
            # light: under 1/tau of the change the old composite (the medium, then the air over it) made,
            # 7-19 % of the brightest pixel under the exp fog (tau at most 69 where T underflows: media_mix's floor)
            old = alone * t_air[..., None] + light
            opaque = close & (t_local < math.exp(-4.0))
            before = np.abs(old - alone).max(-1)
            assert opaque.mean() > 0.2 and before[opaque].max() > 0.03 * alone[opaque].max()
            assert (np.abs(both - alone).max(-1) <= 0.25 * before + 2e-3)[opaque].all(), "an opaque medium hides the air"
    assert np.abs(frame(none, True) - air_alone).max() == 0.0, "a medium of density 0 leaves the air as it was"
    app.close()
    gpu.resize((256, 144))


@pytest.mark.parametrize("froxels, tolerance, rmse_bound", [(None, 8e-3, 5e-3), ((32, 32, 64), 3e-2, 8e-3)])
def test_aerial_perspective_matches_the_float64_march_over_the_ground(gpu, ctx, rng, froxels, tolerance, rmse_bound):
    """C -> L + T C over the ground plane at its distance (the float64 march through the same atmosphere);
    sky pixels untouched; distant ground turns toward the horizon sky; culled and allocating nothing off.
    Every pixel marching (froxels None, against the reference's march of the same steps) and the froxel
    volume read trilinearly (against a 96-step march: its slices' march and its interpolation)."""
    size = (48, 32)
    cases = ((rng.uniform(2, 50), rng.uniform(2, 20), rng.uniform(-0.5, -0.05)),      # near the ground, and high up
             (rng.uniform(800, 6000), rng.uniform(-1, 50), rng.uniform(-0.45, -0.2)))  # near ground and some sky in view
    for altitude, elevation, pitch in cases:
        sun = sun_at(elevation, rng.uniform(0, 360))
        plain, hazed, rays_at, app = ground_frames(gpu, size, altitude, sun,
                                                   math.atan2(sun[0], -sun[2]) + rng.uniform(-1, 1), pitch,
                                                   aerial_froxels=froxels)
        plugin = next(p for p in app.plugins if isinstance(p, SkyPlugin))
        assert "aerial_perspective" in app.graph.compile().kept

        def directions(rays):
            dirs = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
            return dirs, altitude / np.maximum(-dirs[..., 1], 1e-6)
        dirs, distance = directions(rays_at())
        ground = (dirs[..., 1] < -0.01) & (distance < 4e5)          # the plane reaches 5e5 m
        assert ground.mean() > 0.3 and (~ground).any()
        # the GPU's own LUTs (tested against float64 above): this checks the march, not the tables
        tlut, mslut = (plugin.luts.read(name).astype(np.float64) for name in ("transmittance", "multiscattering"))
        steps = plugin.settings.aerial_steps if froxels is None else 96     # the volume marches its own steps
        light, trans = ref.aerial_perspective(plugin.settings.atmosphere, tlut, mslut, altitude, dirs, sun, distance,
                                              steps)
        want = light + trans.mean(-1, keepdims=True) * plain[..., :3]
        err = np.abs(hazed[..., :3] - want)
        # near the horizon a pixel's distance changes fast across it (by half over one row at 20-90 km): the
        # rasteriser places the plane to GL's least sub-pixel precision (4 bits), so each pixel is also allowed
        # the spread of the reference over its ray moved by 1/16 pixel
        spread = np.zeros_like(want)
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            moved, reach = directions(rays_at(dx / 16, dy / 16))
            light_m, trans_m = ref.aerial_perspective(plugin.settings.atmosphere, tlut, mslut, altitude, moved[ground],
                                                      sun, reach[ground], steps)
            spread[ground] = np.maximum(spread[ground], np.abs(light_m + trans_m.mean(-1, keepdims=True)
                                                               * plain[ground][:, :3] - want[ground]))
        beyond = np.maximum(err - spread, 0.0)
        close = ground & (distance < 2e4)   # beyond, a 24-bit depth buffer's distance is off by up to ~1 %
        assert close.mean() > 0.1
        # float32 against float64, the depth buffer's distance and a float16 colour target
        rmse = np.sqrt((beyond[close] ** 2).sum() / (want[close] ** 2).sum())
        # seen (rel. RMSE, worst pixel): marching 3-6e-4, 1e-3 (2.4e-3, 0.56 % once, 20 km from 2.7 km up;
        # 3.6e-3, 0.7 % with seed 3372883879: ground to 20 km from 5.9 km up, the depth buffer's distance);
        # the froxels 4-5e-4, 0.1-0.4 % near the ground, 0.7-4.2e-3, 0.4-1.6 % up high (ground at 15-20 km)
        # a sun within 2 degrees of the horizon: the GPU's march runs up to 1-2 % off the float64 one over 5-20 km
        # (seed 708425170, sun 0.64 degrees: +1 % green and blue, rel. RMSE 4.6e-3), where the sun's
        # transmittance and the multiple-scattering table change fastest with the sun's height; still 1 % at
        # 2.3 degrees from 5.9 km up (seed 1239669340: +0.8 % by 5 km, 5.8 % on the froxels' farthest ground)
        grazing = 3.0 if elevation < 3.0 else 1.0
        assert rmse < grazing * rmse_bound, rmse
        assert (beyond[close] <= grazing * tolerance * np.abs(want[close]) + 3e-4 * want[ground].max()).all(), \
            err[close].max()
        assert (beyond[ground] <= grazing * 5e-2 * np.abs(want[ground])).all(), (beyond[ground] / np.abs(want[ground])).max()
        sky = dirs[..., 1] > 0.01
        assert np.array_equal(hazed[sky], plain[sky]), "the sky already holds the whole ray"
        far = ground & (distance > 20e3)
        if far.any():      # far ground is mostly air light: closer to the sky just above the horizon than to the ground
            assert (trans.mean(-1)[far] < 0.8).all()
        app.close()
    app = physical_app(gpu, GroundPlugin())
    assert "aerial_perspective" not in app.graph.compile().kept
    next(p for p in app.plugins if isinstance(p, SkyPlugin)).configure(model="preetham", aerial_perspective=True)
    app.run_frames(1)
    assert "aerial_perspective" not in app.graph.compile().kept, "the Preetham sky has no atmosphere to march"
    app.close()
    gpu.resize((256, 144))


def test_the_aerial_froxel_volume_is_allocated_only_while_used_and_checked(gpu, ctx):
    """The transient "aerial_volume" exists while the aerial perspective is on with froxels; marching every
    pixel (None) or no aerial perspective allocates none; a bad froxel shape names what is allowed and
    leaves the settings as they were."""
    app = physical_app(gpu, GroundPlugin())
    plugin = next(p for p in app.plugins if isinstance(p, SkyPlugin))
    resources = lambda: app.graph.compile().resources
    app.render()
    assert "aerial_volume" not in resources()
    plugin.configure(aerial_perspective=True)
    app.render()
    assert resources()["aerial_volume"].desc.size == (32, 32, 64)
    plugin.configure(aerial_froxels=None)
    app.render()
    assert "aerial_volume" not in resources() and "aerial_perspective" in app.graph.compile().kept
    for bad in ((0, 32, 32), (32, 32), (32, 32, 300), "32", (32.5, 32, 32)):
        with pytest.raises(ValueError, match=r"SkySettings\.aerial_froxels must be None or three ints in \[1, 256\]"):
            plugin.configure(aerial_froxels=bad)
    assert plugin.settings.aerial_froxels is None
    app.close()


def test_aerial_perspective_hazes_clouds_by_their_own_distance_and_follows_fog(gpu, ctx):
    """With clouds and fog: the pass reads the clouds' distance and runs after the fog; finite frames."""
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin
    density = np.zeros((8, 4, 8), np.float32)
    density[1:7, 1:3, 1:7] = 1.0
    settings = CloudSettings(cell_size=(400.0, 100.0, 400.0), base_altitude=1500.0, group_size=(4, 4))
    app = physical_app(gpu, GroundPlugin(), CloudsPlugin(settings, density=density), CloudRenderPlugin(),
                       FogPlugin(density=1e-4), sun=sun_at(8.0, 20.0), aerial_perspective=True)
    cam = app.resource(Camera)
    cam.position = np.array([-2000.0, 300.0, -2000.0])
    cam.look_at(np.array([1600.0, 1600.0, 1600.0]))
    cam.far = 1e6
    app.run_frames(1)
    kept = app.graph.compile().kept
    assert kept.index("aerial_perspective") > kept.index("fog") > kept.index("cloud_render")
    image = app.read_linear()
    assert np.isfinite(image).all() and image[..., 3].max() > 0.5
    app.close()


# -- the Sun's light from the same model ----------------------------------------------------------------

def test_sun_colour_and_ambient_are_continuous_finite_and_the_reference():
    s = AtmosphereSettings()
    for altitude in (0.0, 20000.0):
        elevations = np.concatenate([[-90.0, -30.0], np.arange(-6.0, 6.01, 0.25), [30.0, 90.0]])
        color = np.array([sun_light.sun_color(sun_at(e), altitude, s) for e in elevations])
        amb = np.array([sun_light.sky_ambient(sun_at(e), altitude, s) for e in elevations])
        assert np.isfinite(color).all() and np.isfinite(amb).all() and (color >= 0).all() and (amb >= 0).all()
        near = slice(2, -2)                                         # the 0.25° steps round the horizon
        fine = np.array([sun_light.sun_color(sun_at(e), altitude, s) for e in np.arange(-6.0, 6.01, 0.05)])
        steps = np.abs(np.diff(color[near], axis=0)).max()
        assert np.abs(np.diff(fine, axis=0)).max() < 0.35 * steps, "the sun's colour has no jump (5× finer, 5× smaller steps)"
        assert np.abs(np.diff(amb[near], axis=0)).max() < 0.05 * amb[near].max(), "no jump in the ambient"
        dip = math.degrees(math.acos(s.planet_radius / (s.planet_radius + altitude)))   # the horizon's depression
        assert (color[elevations < -dip - 0.5] == 0).all() and (color[elevations > -dip + 0.5] > 0).all()
        for e in (-3.0, 0.3, 7.7, 45.2):                            # interpolated nodes vs the direct integral
            direct = ref.ambient(sun_at(e), altitude, s)
            assert np.allclose(sun_light.sky_ambient(sun_at(e), altitude, s), direct, rtol=0.05, atol=1e-4)
    noon = sun_light.sun_color(sun_at(68.4), 0.0, s)
    from atmos.lighting import sky_light
    assert np.allclose(noon, sky_light(sun_at(68.4))[0], rtol=0.01), "calibrated: a noon sun as before"
    low = sun_light.sun_color(sun_at(2.0), 0.0, s)
    assert low[0] > 3 * low[1] > 9 * low[2], "a low sun is red"
    high = sun_light.sun_color(sun_at(2.0), 20000.0, s)
    assert (high > low).all(), "above most of the air it is brighter and whiter"


def test_frames_stay_finite_at_the_extremes(gpu, ctx):
    gpu.resize((32, 24))
    for altitude in (0.0, 20000.0, 2e5):                   # 200 km: above the atmosphere
        for elevation in (-90.0, 0.0, 90.0):
            for pitch in (0.1, -1.5):                           # the aerial perspective over the ground straight down
                app = physical_app(gpu, GroundPlugin(half_size=1e6), sun=sun_at(elevation, 30.0), altitude=altitude,
                                   aerial_perspective=pitch < 0)
                cam = app.resource(Camera)
                cam.pitch, cam.far = pitch, 1e7
                app.run_frames(1, 1 / 30)
                img = app.read_linear()
                sun = app.resource(Sun)
                assert np.isfinite(img).all() and np.isfinite(sun.color).all() and np.isfinite(sun.ambient).all()
                assert np.isfinite(sun.color_at(altitude + 1000.0)).all()
                app.close()
    gpu.resize((256, 144))


def test_the_sun_light_follows_daylight_by_label_whatever_the_plugin_order(gpu, ctx):
    for order in (0, 1):
        daylight = DaylightPlugin(hours=19.3)
        sky = SkyPlugin(model="physical")
        plugins = [daylight, sky] if order else [sky, daylight]
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), *plugins)
        app.startup()
        app.resource(Camera).position = np.array([0.0, 300.0, 0.0])
        app.update(1 / 30)
        sun = app.resource(Sun)
        assert np.allclose(sun.color, sun_light.sun_color(sun.direction, 300.0, sky.settings.atmosphere))
        labels = [s.label for s in app.schedule.build()["update"]]
        assert labels.index("daylight") < labels.index("sky_light")
        declared = {s.label: s.after for s in app.schedule.systems}
        assert declared["sky_light"] == ("daylight",) and declared["sky_light_start"] == ("daylight_start",)
        app.close()


# -- settings, culling, allocation ----------------------------------------------------------------------

def test_settings_errors_name_the_field():
    for kwargs, match in ((dict(model="bruneton"), "SkySettings.model must be one of 'preetham', 'physical'"),
                          (dict(atmosphere=3), "SkySettings.atmosphere must be an AtmosphereSettings")):
        with pytest.raises(ValueError, match=match):
            SkySettings(**kwargs)
    for kwargs, match in ((dict(mie_g=1.0), "AtmosphereSettings.mie_g"),
                          (dict(ground_albedo=(0.5, 1.5, 0.5)), r"AtmosphereSettings.ground_albedo must be 3 numbers in \[0, 1\]"),
                          (dict(rayleigh_scattering=(5.8, 13.6, 33.1)), "AtmosphereSettings.rayleigh_scattering must be 3 coefficients"),
                          (dict(planet_radius=float("nan")), "AtmosphereSettings.planet_radius")):
        with pytest.raises(ValueError, match=match):
            AtmosphereSettings(**kwargs)
    plugin = SkyPlugin(model="physical")
    with pytest.raises(ValueError, match="unknown AtmosphereSettings setting"):
        plugin.configure(atmosphere={"nosuch": 1})
    with pytest.raises(ValueError, match="AtmosphereSettings.mie_g"):
        plugin.configure(turbidity=3.0, atmosphere={"mie_g": 2.0})
    assert plugin.settings.turbidity == SkySettings().turbidity, "nothing half-applied"
    assert plugin.configure(atmosphere={"mie_g": 0.7}).atmosphere.mie_g == 0.7


def test_luts_only_with_the_physical_model_and_recomputed_only_when_inputs_change(fresh_gpu):
    gpu = fresh_gpu
    sky = SkyPlugin()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), sky, GroundPlugin())
    app.insert_resource(Sun(direction=sun_at(20.0)))
    app.run_frames(2, 1 / 30)
    assert "sky_luts" in app.graph.compile().culled and sky.luts is None, "Preetham: no LUT pass, no textures"
    sky.configure(model="physical")
    app.run_frames(1, 1 / 30)
    luts = sky.luts
    assert luts is not None and luts.builds == [1, 1, 1] and "sky_luts" not in app.graph.compile().culled
    app.run_frames(2, 1 / 30)
    assert luts.builds == [1, 1, 1], "nothing changed: nothing recomputed"
    app.resource(Sun).direction = sun_at(20.0, 120.0)
    app.run_frames(1, 1 / 30)
    assert luts.builds == [1, 1, 1], "the sun's azimuth alone changes no LUT"
    app.resource(Sun).direction = sun_at(20.01, 120.0)
    app.run_frames(1, 1 / 30)
    assert luts.builds == [1, 1, 1], "nor a move of the sun within SUN_TOLERANCE"
    app.resource(Sun).direction = sun_at(19.0)
    app.run_frames(1, 1 / 30)
    assert luts.builds == [1, 1, 2], "the sun's height: the sky view only"
    app.resource(Camera).position = np.array([0.0, 800.0, 0.0])
    app.run_frames(1, 1 / 30)
    assert luts.builds == [1, 1, 3], "the camera's altitude: the sky view only"
    sky.configure(atmosphere={"mie_g": 0.6})
    app.run_frames(1, 1 / 30)
    assert luts.builds == [2, 2, 4], "the atmosphere: everything"
    sky.configure(model="preetham")
    app.run_frames(1, 1 / 30)
    assert sky.luts is None and not luts.textures, "back to Preetham: the LUTs are released"
    app.close()


# -- composition ----------------------------------------------------------------------------------------

def test_fog_colour_follows_the_physical_sky(gpu, ctx):
    sun = sun_at(3.0, 40.0)
    app = physical_app(gpu, GroundPlugin(), FogPlugin(mode="exp", density=1e-3, color_from="sky", sky="keep",
                                                      fog_color=(1.0, 1.0, 1.0)), sun=sun, altitude=150.0, stars=False)
    app.run_frames(1, 1 / 30)
    fog = next(p for p in app.plugins if isinstance(p, FogPlugin))
    sky = next(p for p in app.plugins if isinstance(p, SkyPlugin))
    from atmos.scene_view import SceneView
    view = SceneView(camera=app.resource(Camera), sun=app.resource(Sun), clock=app.clock, size=gpu.size)
    table = fog.horizon(view)
    dirs = horizon_directions(len(table))
    direct = ref.sky_radiance(dirs, sun, 150.0, sky.settings.atmosphere)
    assert np.allclose(table, direct, rtol=0.05), "the fog's horizon is the physical sky's"
    drawn = ref.sample_sky_view(sky.settings.atmosphere, sky.luts.read("sky_view").astype(np.float64), 150.0, dirs, sun)
    assert np.allclose(table, drawn, rtol=0.05), "... and what the sky pass draws there"
    toward, away = table[np.argmax(dirs @ sun)], table[np.argmin(dirs @ sun)]
    assert toward[0] > 3 * away[0] and toward[0] > toward[2], "orange toward the low sun"
    app.close()


def test_clouds_are_lit_by_the_physical_sun_colour():
    from atmos.plugins.clouds.volume.light import light_uniforms
    from atmos.plugins.clouds import CloudSettings
    sun = Sun(direction=sun_at(2.0))
    s = AtmosphereSettings()
    sun.color = tuple(sun_light.sun_color(sun.direction, 900.0, s))
    sun.ambient = tuple(sun_light.sky_ambient(sun.direction, 900.0, s))
    sources = np.array(light_uniforms(CloudSettings(), sun)["sun_sources"])
    assert np.all(sources == sources[0]), "without a layer, the camera's colour at every height"
    source = sources[0]
    ratio = source / np.asarray(sun.color)
    assert np.allclose(ratio, ratio[0], rtol=1e-5), "the clouds' sun is Sun.color, scaled"
    assert source[0] > 3 * source[2], "sunset clouds get the reddened sun"


def test_clouds_above_keep_the_sun_after_the_grounds_sunset(gpu, ctx):
    """The physical sky gives the sun's colour by altitude: at -0.8 deg the ground has lost the sun, a layer
    1.5 km up has not (the horizon dips 1.2 deg there); by day the layer sees it through less air.
    The clouds take it at their heights; the Preetham model gives none, and switching back drops it."""
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds.volume.light import light_uniforms
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin
    s = AtmosphereSettings()
    low = Sun(direction=sun_at(-0.8))
    assert np.all(sun_light.sun_color(low.direction, 0.0, s) == 0.0)
    high = sun_light.sun_color(low.direction, 1500.0, s)
    assert high[0] > 0.05 and high[0] > 3 * high[2], high
    day = sun_at(20.0)
    assert np.all(sun_light.sun_color(day, 2000.0, s) > sun_light.sun_color(day, 0.0, s))

    density = np.zeros((8, 4, 8), np.float32)
    density[1:7, 1:3, 1:7] = 1.0
    settings = CloudSettings(cell_size=(60.0, 50.0, 60.0), base_altitude=1500.0, group_size=(4, 4))
    plugin = SkyPlugin(model="physical")
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), plugin, CloudsPlugin(settings, density=density),
                               CloudRenderPlugin())
    app.insert_resource(Sun(direction=sun_at(-0.8, 45.0)))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([-300.0, 2.0, -300.0])
    cam.look_at(np.array([240.0, 1600.0, 240.0]))
    app.run_frames(1)
    sun = app.resource(Sun)
    assert np.all(np.asarray(sun.color) == 0.0) and sun.color_by_altitude is not None
    lit = np.asarray(light_uniforms(settings, sun, layer=(1500.0, 1700.0))["sun_sources"])
    assert lit[:, 0].min() > 0.1 and np.all(np.asarray(light_uniforms(settings, sun)["sun_sources"]) == 0.0)
    image = app.read_linear()
    clouds = image[..., 3] > 0.5
    assert clouds.mean() > 0.02, "the view must see the clouds"
    red_lit = image[clouds, 0].mean()
    plugin.configure(model="preetham")    # no colour by altitude: the clouds get the ground's (none), sky light only
    app.run_frames(1)
    assert app.resource(Sun).color_by_altitude is None
    unlit = app.read_linear()[clouds, 0].mean()
    assert red_lit > 1.5 * unlit, (red_lit, unlit)
    app.close()


def test_a_sun_colour_by_altitude_is_checked():
    with pytest.raises(ValueError, match="Sun.color_by_altitude must be None or a callable"):
        Sun(color_by_altitude=(1.0, 0.5, 0.2))
    sun = Sun(color_by_altitude=lambda d, h: np.stack([np.ones_like(h), np.full_like(h, np.nan), 0 * h], -1))
    with pytest.raises(ValueError, match=r"Sun.color_by_altitude must return \(1, 3\) non-negative finite numbers"):
        sun.color_at(100.0)
    one_colour = Sun(color_by_altitude=lambda d, h: (1.0, 0.5, 0.2))     # not vectorised over the altitudes
    with pytest.raises(ValueError, match=r"must return \(8, 3\) non-negative finite numbers for 8 altitudes"):
        one_colour.color_at(np.linspace(0.0, 700.0, 8))
    assert np.array_equal(Sun(color=(0.5, 0.4, 0.3)).color_at(5000.0), [0.5, 0.4, 0.3])
    assert Sun(color=(0.5, 0.4, 0.3)).color_at([1.0, 2.0]).shape == (2, 3)


# -- the Monte-Carlo check and the demos ------------------------------------------------------------------

def test_the_path_tracer_first_order_is_the_single_scattering_model():
    """The independent check's own check: the tracer stopped after one scattering event equals the
    model's single scattering (no LUT, no Ψms) within its noise; all orders add light."""
    from atmos.plugins.sky.atmosphere_paths import trace
    single = AtmosphereSettings(multiple_scattering=0.0)
    sun = sun_at(20.0)
    for view in (np.array([0.0, 1.0, 0.0]), sun_at(5.0, 150.0)):
        mc, err = trace(view, sun, 0.0, single, paths=3000, seed=3, max_orders=1)
        model = ref.sky_radiance(view[None], sun, 0.0, single, steps=64)[0]
        assert (np.abs(mc - model) < 4 * err + 0.01 * model).all(), (mc, err, model)
        more, _ = trace(view, sun, 0.0, single, paths=3000, seed=3)
        assert (more > mc).all()


def test_the_demos_take_the_sky_model(gpu, ctx, capsys):
    from atmos.cli import main
    from atmos.demo_registry import SKY_MODELS, DemoSettings
    from atmos.plugins.sky import MODELS
    assert SKY_MODELS == MODELS
    with pytest.raises(ValueError, match="DemoSettings.sky must be one of 'preetham', 'physical'"):
        DemoSettings(sky="bruneton")
    assert main(["graph", "sky_day", "--sky", "physical"]) == 0
    assert "2. sky_luts" in capsys.readouterr().out, "the LUT pass runs before the sky pass"


@pytest.mark.parametrize("renderer", ["sprites", "march"])
def test_at_dusk_the_tops_keep_the_sun_after_the_bases_lose_it(gpu, ctx, renderer, monkeypatch):
    """A tower of cloud from 900 m to 2.1 km, the sun 1.2 deg below the horizon: the physical sky's sun has
    all but set for the base (the planet's shadow: 0.6 % of the top's red) and not for the top. Both
    renderers take the sun's colour at each height (volume.glsl sun_source_at): the top glows red over a
    base lit by the sky alone. Drawn again with the middle's colour at every height (the model before),
    the base is brighter and the top darker. The march draws it as congestus (cloud_type 1: a tower to the
    layer's top)."""
    from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds.volume import light
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin

    def draw():
        density = np.zeros((8, 24, 8), np.float32)
        density[1:7, 1:23, 1:7] = 1.0
        settings = CloudSettings(cell_size=(50.0, 50.0, 50.0), base_altitude=900.0, group_size=(4, 4), sigma_t=0.01)
        drawing = CloudRenderPlugin() if renderer == "sprites" else RaymarchCloudsPlugin(jitter=False, cloud_type=1.0)
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin(model="physical"),
                                   CloudsPlugin(settings, density=density), drawing)
        app.insert_resource(Sun(direction=sun_at(-1.2, 60.0)))
        app.startup()
        cam = app.resource(Camera)
        cam.position, cam.far = np.array([200.0, 900.0, -2500.0]), 20000.0
        cam.look_at(np.array([200.0, 1500.0, 200.0]))
        app.run_frames(1)
        image = app.read_linear()
        app.close()
        rows = np.flatnonzero((image[..., 3] > 0.5).any(1))
        assert len(rows) > 10 and np.isfinite(image).all(), "the view must see the tower"
        third = len(rows) // 3
        return [float(part[part[..., 3] > 0.5, 0].mean()) for part in (image[rows[:third]], image[rows[-third:]])]

    top, base = draw()
    middle = light.sun_colors
    monkeypatch.setattr(light, "sun_colors", lambda sun, layer=None: middle(sun, None if layer is None else (
        0.5 * (layer[0] + layer[1]),) * 2))
    flat_top, flat_base = draw()
    assert top > 1.6 * base and top > 1.1 * flat_top and base < 0.9 * flat_base, (top, base, flat_top, flat_base)


def test_the_sun_by_height_stays_finite_at_the_extremes():
    """The cloud light's sun colours by height (light.sun_colors through the physical sky's vectorised
    sun_radiance) for layers below the ground, of no height, above the atmosphere's top, and a sun from
    the zenith to 30 deg below the horizon: finite, non-negative, one row per height, and none once the
    layer's sun has set."""
    from atmos.plugins.clouds.volume.light import SUN_HEIGHTS, light_uniforms, sun_colors
    from atmos.plugins.clouds import CloudSettings
    s = AtmosphereSettings()
    for elevation in (90.0, 10.0, 0.0, -0.5, -2.0, -30.0):
        sun = Sun(direction=sun_at(elevation, 40.0))
        sun.color_by_altitude = lambda d, h: sun_light.sun_color(d, h, s)
        for layer in ((-500.0, -100.0), (1500.0, 1500.0), (900.0, 2100.0), (9e4, 2e5)):
            colors = sun_colors(sun, layer)
            assert colors.shape == (SUN_HEIGHTS, 3) and np.isfinite(colors).all() and colors.min() >= 0.0
            sources = np.asarray(light_uniforms(CloudSettings(), sun, layer=layer)["sun_sources"])
            assert np.isfinite(sources).all() and sources.min() >= 0.0
            if elevation <= -30.0:
                assert colors.max() == 0.0, "a sun 30 deg down has set for every layer"


def test_a_sun_crossing_a_light_table_node_finds_it_baked_ahead(gpu, ctx):
    """The sun's ambient and the fog's horizon rings interpolate nodes 0.5° of sun elevation apart, each
    3-5 ms of float64 marching: the nodes one step from those in use are baked ahead, one a frame, so
    the sun rising through four nodes (and the fog's rings with it) never bakes more than one node in a
    frame once under way; the values are the nodes' own (as baked when first used)."""
    from atmos.plugins.sky import sun_light
    sun_light._NODES.clear()                         # the nodes are kept per process: earlier tests may hold these
    sun_light._USED.clear()
    app = physical_app(gpu, FogPlugin(mode="exp", density=1e-4, color_from="sky"), sun=sun_at(10.0))
    try:
        app.run_frames(4, 1 / 30)
        sun, grew = app.resource(Sun), []
        for k in range(1, 41):                       # 10° -> 12°: four node crossings, 10 frames apart
            sun.direction = sun_at(10.0 + 0.05 * k)
            before = len(sun_light._NODES)
            app.update(1 / 30)
            grew.append(len(sun_light._NODES) - before)
        assert max(grew) <= 1, f"nodes baked per frame {grew}: a crossing baked several at once"
        assert sum(grew) >= 4, "the crossings' nodes were baked (ahead)"
        s = next(p for p in app.plugins if isinstance(p, SkyPlugin)).settings.atmosphere
        direct = sun_light._bake_ambient(s, 24, 0)
        assert np.array_equal(sun_light._node(sun_light._bake_ambient, s, 24, 0), direct)
    finally:
        app.close()
