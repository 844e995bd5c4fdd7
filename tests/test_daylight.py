import math

import numpy as np
import pytest

from atmos.app import App
from atmos.lighting import Sun
from atmos.plugins.daylight import DaylightPlugin, solar_direction


def elevation(d):
    return math.degrees(math.asin(d[1]))


def test_noon_elevation_and_symmetry():
    for lat, day in ((45.0, 172), (45.0, 355), (0.0, 80), (-30.0, 172)):
        delta = -23.44 * math.cos(2 * math.pi * (day + 10) / 365)
        assert elevation(solar_direction(12.0, lat, day)) == pytest.approx(90 - abs(lat - delta), abs=1e-6)
        morning, evening = solar_direction(9.0, lat, day), solar_direction(15.0, lat, day)
        assert morning[0] == pytest.approx(-evening[0]) and morning[1] == pytest.approx(evening[1])
    assert solar_direction(6.0)[0] > 0.8                # rises in the east
    assert solar_direction(0.0)[1] < 0                  # midnight: below the horizon


def test_directions_are_unit_and_continuous():
    hours = np.linspace(0, 24, 2401)
    dirs = np.array([solar_direction(h) for h in hours])
    assert np.allclose(np.linalg.norm(dirs, axis=1), 1.0)
    assert np.max(np.linalg.norm(np.diff(dirs, axis=0), axis=1)) < 0.01


def test_plugin_drives_the_sun_through_a_day():
    app = App().add_plugins(DaylightPlugin(hours=11.0, speed=2.0))     # two in-game hours per second
    colors, elevations = [], []
    for _ in range(12 * 30):                                           # 12 s: one whole day
        app.update(1 / 30)
        sun = app.resource(Sun)
        colors.append(sum(sun.color))
        elevations.append(elevation(sun.direction))
    colors, elevations = np.array(colors), np.array(elevations)
    assert elevations.max() > 60 and elevations.min() < -15
    assert np.all(colors[elevations < -1] == 0.0), "no direct sun at night"
    assert colors[elevations > 30].min() > 1.0
    assert sum(app.resource(Sun).ambient) > 0 and np.isfinite(colors).all()
    app.close()


@pytest.mark.parametrize("fields, message", [
    ({"hours": 25.0}, r"DaylightSettings.hours must be a finite number >= 0.0 and <= 24.0, got 25.0"),
    ({"latitude": float("nan")}, "latitude"),
    ({"speed": float("inf")}, "speed must be a finite number"),
])
def test_bad_time_of_day(fields, message):
    with pytest.raises(ValueError, match=message):
        DaylightPlugin(**fields)
