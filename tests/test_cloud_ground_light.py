"""The clouds' shadow on the ground as their light from below sees it (plugins/clouds/light/ground.py):
G on the GPU against its float64 twin on random columns; the ground's radiance it scales
(medium.environment) and the scene's ground albedo reaching the light block."""
import dataclasses

import numpy as np
import pytest

from atmos.graph import RenderPass
from atmos.lighting import GroundSurface, Sun
from atmos.plugins.clouds.light.ground import GROUND, ground_sun_pass, ground_sun_reference
from atmos.plugins.clouds.light.medium import environment
from atmos.plugins.clouds.shadows import CloudShadowSettings
from atmos.plugins.clouds.simulation.chain import CloudSettings
from atmos.plugins.clouds.volume.light import light_uniforms
from test_cloud_shadows import draw_typed, shadow_app, write_sums


class GroundCapture(RenderPass):
    """Reads "cloud_ground" back after the frame's bake."""
    name = "cloud_ground_capture"
    phase = "post"
    value = None

    def setup(self, builder) -> None:
        builder.read(GROUND, access="copy")
        builder.side_effect()

    def execute(self, frame) -> None:
        self.value = np.frombuffer(frame.resource(GROUND).read(), np.float32).astype(np.float64)


@pytest.mark.parametrize("fade, typed", [(0.0, None), (0.35, None), (0.0, "type"), (0.35, "map")])
def test_gpu_ground_sun_matches_float64(gpu, ctx, rng, fade, typed):
    """G from random column sums of A and B (t between them) within float32's rounding of a 4,096-term
    mean of values in [0, 1]; more shadow, smaller G; with the clouds drawn with a cloud type (one, or a
    map) each column is the shape drawn (typed_column)."""
    app, sim, _, _ = shadow_app(gpu, CloudShadowSettings())
    types = draw_typed(app, sim, rng, typed)
    sim.settings = dataclasses.replace(sim.settings, edge_fade=fade)      # as CloudsPlugin.configure does
    ground_sun_pass(app.graph)
    capture = GroundCapture()
    app.graph.add_pass(capture)
    for _ in range(2):
        app.update(1 / 30)
    a, b, t = sim.view()
    nx, ny, nz = sim.shape
    layers = 1 + sim.maps_of(a).bands
    got = []
    for scale in (0.2, 1.0):
        sums = [rng.uniform(0, scale * ny, (layers, nx, nz)) for _ in range(2)]
        write_sums(sim, a, sums[0])
        write_sums(sim, b, sums[1])
        app.render()
        sets = sim.sets()
        want = ground_sun_reference(sums[0][0], sums[1][0], sets.t, sets.layout(), sim.settings.sigma, fade, **types)
        assert capture.value[0] == pytest.approx(want, abs=2e-6), (capture.value, want)
        assert np.all(capture.value[1:] == 0.0)
        got.append(want)
    assert 0.0 < got[1] < got[0] < 1.0
    app.close()


def test_ground_radiance_follows_albedo_and_shadow():
    """environment(): the ground's radiance is albedo × (E sun_y G / pi + L_sky): under a full shadow the
    sky's part only; a GroundSurface's albedo replaces the medium's in the light block."""
    s = CloudSettings()
    sun_dir = np.array([0.0, 0.6, -0.8])
    e, sky, lit = environment(s, (1.0, 0.9, 0.8), (0.3, 0.4, 0.6), sun_dir)
    _, _, shadowed = environment(s, (1.0, 0.9, 0.8), (0.3, 0.4, 0.6), sun_dir, ground_sun=0.0)
    assert shadowed == pytest.approx(s.ground_albedo * sky)
    assert lit - shadowed == pytest.approx(s.ground_albedo * e * 0.6 / np.pi)
    _, _, grass = environment(s, (1.0, 0.9, 0.8), (0.3, 0.4, 0.6), sun_dir, albedo=(0.1, 0.2, 0.05), ground_sun=0.5)
    assert grass == pytest.approx(np.array([0.1, 0.2, 0.05]) * (e * 0.6 * 0.5 / np.pi + sky))
    sun = Sun(direction=sun_dir, color=(1.0, 0.9, 0.8), ambient=(0.3, 0.4, 0.6))
    default, green = light_uniforms(s, sun), light_uniforms(s, sun, ground=GroundSurface((0.1, 0.2, 0.05)).albedo)
    assert np.asarray(green["ground_sky_source"]) == pytest.approx(0.5 * s.albedo * np.array([0.1, 0.2, 0.05]) * sky)
    assert np.asarray(default["ground_sun_source"]) == pytest.approx(0.5 * s.albedo * s.ground_albedo * e * 0.6 / np.pi)
    assert default["sky_source"] == green["sky_source"]


def test_ground_surface_checks_its_albedo():
    with pytest.raises(ValueError, match="GroundSurface.albedo"):
        GroundSurface((0.5, 1.5, 0.2))
    with pytest.raises(ValueError, match="GroundSurface"):
        GroundSurface((0.5, float("nan"), 0.2))
    assert GroundSurface(lambda: (2.0, 0.5, -1.0)).albedo == (1.0, 0.5, 0.0)     # a drawing plugin's value, clamped


def test_terrain_and_ground_publish_their_albedo(gpu, ctx):
    """TerrainPlugin and GroundPlugin insert the GroundSurface the clouds' light reads, following live changes."""
    from atmos import App, DefaultPlugins
    from atmos.plugins.ground import GroundPlugin
    from atmos.plugins.terrain import TerrainPlugin
    terrain = TerrainPlugin(size=4000.0, cells=16, relief=300.0, horizon=2000.0)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), terrain)
    app.startup()
    surface = app.resource(GroundSurface)
    assert surface.albedo == pytest.approx(tuple(terrain.mean_albedo))
    before = surface.albedo
    terrain.configure(snowline=0.1)                 # snow on most of it: brighter
    assert sum(surface.albedo) > sum(before) + 0.1
    app.close()
    ground = GroundPlugin(albedo=(0.1, 0.2, 0.3))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), ground)
    app.startup()
    assert app.resource(GroundSurface).albedo == (0.1, 0.2, 0.3)
    ground.configure(albedo=(0.5, 0.5, 0.5))
    assert app.resource(GroundSurface).albedo == (0.5, 0.5, 0.5)
    app.close()


def test_the_ground_plane_fades_into_the_skys_own_light(gpu, ctx):
    """Far ground takes HAZE_GAIN × the Sun's ambient (a twilight sky's is dim: no bright line at the
    horizon); haze_distance 0 keeps the plane's own shading to its edge."""
    from atmos import App, Camera, DefaultPlugins
    from atmos.plugins.ground import GroundPlugin
    ambient = (0.03, 0.02, 0.025)
    for distance in (667.0, 0.0):
        app = App(gpu).insert_resource(Sun(direction=np.array([0.0, -0.05, -1.0]), color=(0.0, 0.0, 0.0),
                                           ambient=ambient))
        app.add_plugins(DefaultPlugins(overlay=False), GroundPlugin(half_size=4e4, haze_distance=distance))
        app.startup()
        cam = app.resource(Camera)
        cam.position, cam.far = np.array([0.0, 50.0, 0.0]), 1e5
        cam.yaw, cam.pitch = 0.0, 0.0
        image = app.read_linear()
        app.close()
        far = image[image.shape[0] // 2, :, :3].mean(axis=0)     # half a pixel under the horizon: kilometres away
        if distance:
            assert far == pytest.approx(2.0 * np.asarray(ambient), rel=0.05)
        else:
            assert np.all(far < 0.3 * 2.0 * np.asarray(ambient)), "its own shade: the albedo times the ambient"
    from atmos.plugins.sky import SkyPlugin, SkyLight
    from atmos.plugins.ground import haze_color
    for elevation in (30.0, -3.0):                   # with a sky: its mean horizon light, day and twilight
        app = App(gpu).insert_resource(Sun.from_angles(elevation, 40.0))
        app.add_plugins(DefaultPlugins(overlay=False), SkyPlugin(model="physical", stars=False), GroundPlugin(half_size=4e4))
        app.startup()
        cam = app.resource(Camera)
        cam.position, cam.far = np.array([0.0, 50.0, 0.0]), 1e5
        cam.yaw, cam.pitch = 0.0, 0.0
        image = app.read_linear()
        want = app.resource(SkyLight).mean_horizon(app.resource(Sun), 50.0)
        view = type("View", (), {"sun": app.resource(Sun), "camera": cam})
        assert haze_color(view, app.resource(SkyLight)) == pytest.approx(want)
        app.close()
        assert image[image.shape[0] // 2, :, :3].mean(axis=0) == pytest.approx(want, rel=0.03)
