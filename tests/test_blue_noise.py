"""The blue-noise tile the ray march offsets its first samples by (atmos/blue_noise.py)."""
import numpy as np
import pytest

from atmos.blue_noise import blue_noise


def low_frequency_share(tile) -> float:
    """The power below an eighth of the tile's frequencies over the mean power (white noise: about 1)."""
    n = tile.shape[0]
    power = np.abs(np.fft.fft2(tile - tile.mean())) ** 2
    k = np.fft.fftfreq(n) * n
    radius = np.hypot(k[:, None], k[None, :])
    return float(power[(radius > 0) & (radius < n / 8)].mean() / power[radius > 0].mean())


def nearest_spacing(points, n) -> float:
    d = np.abs(points[:, None, :] - points[None, :, :])
    d = np.minimum(d, n - d)                         # the tile wraps
    distance = np.hypot(d[..., 0], d[..., 1])
    np.fill_diagonal(distance, np.inf)
    return float(distance.min())


@pytest.mark.parametrize("size, seed", [(64, 0), (32, 7)])
def test_blue_noise_is_uniform_without_low_frequencies_and_evenly_spread(rng, size, seed):
    made = blue_noise(size, 1.5, seed)
    assert made.shape == (size, size) and made.dtype == np.float32
    tile, n = made.astype(np.float64), size * size
    assert np.allclose(np.sort(tile.ravel()), (np.arange(n) + 0.5) / n), "every value once: uniform"
    white = rng.random((size, size))
    y, x = np.mgrid[0:size, 0:size]
    gradient = np.mod(52.9829189 * np.mod(0.06711056 * x + 0.00583715 * y, 1.0), 1.0)   # the offset it replaced
    assert low_frequency_share(tile) < 0.01 * min(low_frequency_share(white), low_frequency_share(gradient))
    for share in (1 / 64, 1 / 16):                   # any threshold is a spread-out point set
        points = np.argwhere(tile < share)
        ideal = 1.0 / np.sqrt(share)
        assert nearest_spacing(points, size) >= 0.6 * ideal > nearest_spacing(np.argwhere(white < share), size)
    assert blue_noise(size, 1.5, seed) is blue_noise(size, 1.5, seed), "made once"
