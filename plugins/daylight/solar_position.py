"""Where the sun is: the Astronomical Almanac's low-precision solar coordinates (Michalsky 1988).

Within about 0.01° of NREL's Solar Position Algorithm for 1950–2050 (tests/test_daylight.py holds
it to a table of SPA values). Days count from J2000.0: ``n = JD − 2451545``; mean longitude
``L = 280.460° + 0.9856474° n``, mean anomaly ``g = 357.528° + 0.9856003° n``, ecliptic longitude
``λ = L + 1.915° sin g + 0.020° sin 2g``, obliquity ``ε = 23.439° − 4e-7° n``; right ascension and
declination from λ and ε; Greenwich mean sidereal time ``6.697375 h + 0.0657098242 h n + UT``.
The equation of time is the difference between the mean sun (L) and the right ascension.

Two ways to give the time:

- **solar time** (no longitude): ``hours`` is local apparent solar time, so the hour angle is
  exactly ``15° (hours − 12)`` (noon: the sun due south or north); only the declination comes from
  the date.
- **clock time**: with a ``longitude`` (degrees, east positive), ``hours`` is the clock in the time
  zone ``utc_offset`` hours from UTC (default: the longitude's nominal zone, ``round(lon / 15)``);
  the hour angle then includes the equation of time, as a real clock shows it.

The elevation returned is the apparent one: refraction for a standard atmosphere (1010 hPa, 10 °C,
SPA's formula) is added above −0.83° and faded out over the next degree below, so the sun's path
stays continuous through the horizon.
"""
from __future__ import annotations

import datetime
import math

import numpy as np

J2000 = datetime.datetime(2000, 1, 1, 12)
REFRACTION_FADE = (-1.83, -0.83)     # apparent elevations (°) over which refraction fades in


def days_since_j2000(year: int, day_of_year: float, ut_hours: float) -> float:
    """Days from J2000.0 (2000-01-01 12:00) to UT ``ut_hours`` on day ``day_of_year`` (1 = 1 January) of ``year``."""
    start = (datetime.datetime(int(year), 1, 1) - J2000).total_seconds() / 86400.0
    return start + (day_of_year - 1.0) + ut_hours / 24.0


def sun_coordinates(n: float) -> tuple[float, float, float]:
    """(declination °, right ascension °, equation of time in hours) at ``n`` days from J2000.0."""
    mean_lon = (280.460 + 0.9856474 * n) % 360.0
    g = math.radians((357.528 + 0.9856003 * n) % 360.0)
    lam = math.radians(mean_lon + 1.915 * math.sin(g) + 0.020 * math.sin(2.0 * g))
    eps = math.radians(23.439 - 4e-7 * n)
    ra = math.degrees(math.atan2(math.cos(eps) * math.sin(lam), math.cos(lam))) % 360.0
    dec = math.degrees(math.asin(math.sin(eps) * math.sin(lam)))
    eot = ((mean_lon - ra + 180.0) % 360.0 - 180.0) / 15.0
    return dec, ra, eot


def refraction(elevation: float) -> float:
    """Atmospheric refraction (°) to add to a true elevation (°): SPA's formula at 1010 hPa, 10 °C."""
    if elevation < REFRACTION_FADE[0]:
        return 0.0
    e = max(elevation, REFRACTION_FADE[1])
    r = 1.02 / (60.0 * math.tan(math.radians(e + 10.3 / (e + 5.11))))
    lo, hi = REFRACTION_FADE
    return r * min(1.0, (elevation - lo) / (hi - lo))


def solar_position(hours: float, latitude: float, day_of_year: float, year: int = 2024,
                   longitude: float | None = None, utc_offset: float | None = None) -> tuple[float, float]:
    """(apparent elevation °, azimuth ° clockwise from north) of the sun; the module docstring says
    what ``hours`` means with and without a ``longitude``."""
    if longitude is None:
        # solar time: the hour angle is exact; the date (taken at longitude 0) only sets the declination
        dec, _, _ = sun_coordinates(days_since_j2000(year, day_of_year, hours))
        h = 15.0 * (hours - 12.0)
    else:
        offset = round(longitude / 15.0) if utc_offset is None else utc_offset
        n = days_since_j2000(year, day_of_year, hours - offset)
        dec, ra, _ = sun_coordinates(n)
        gmst = (6.697375 + 0.0657098242 * n + (hours - offset)) % 24.0
        h = (gmst * 15.0 + longitude - ra + 180.0) % 360.0 - 180.0
    phi, d, hr = math.radians(latitude), math.radians(dec), math.radians(h)
    east = -math.cos(d) * math.sin(hr)
    north = math.sin(d) * math.cos(phi) - math.cos(d) * math.cos(hr) * math.sin(phi)
    up = math.sin(d) * math.sin(phi) + math.cos(d) * math.cos(hr) * math.cos(phi)
    elevation = math.degrees(math.atan2(up, math.hypot(east, north)))
    azimuth = math.degrees(math.atan2(east, north)) % 360.0
    return elevation + refraction(elevation), azimuth


def solar_direction(hours: float, latitude: float = 45.0, day_of_year: float = 172.0, year: int = 2024,
                    longitude: float | None = None, utc_offset: float | None = None) -> np.ndarray:
    """Unit vector toward the sun (x east, y up, −z north) from :func:`solar_position`; below the
    horizon it points below it (y < 0): night."""
    e, a = map(math.radians, solar_position(hours, latitude, day_of_year, year, longitude, utc_offset))
    return np.array([math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)])
