"""float64 reference of ``mesh/mesh.frag``: the colour of a mesh surface."""
import numpy as np


def mesh_color(color, normal, sun_dir, sun_color, sky_ambient) -> np.ndarray:
    """``color`` × (sun × max(n·s, 0) + sky ambient × (0.6 + 0.4 n_y)) for unit-normalised n and s."""
    n = np.asarray(normal, np.float64)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    s = np.asarray(sun_dir, np.float64)
    s = s / np.linalg.norm(s)
    lambert = np.maximum((n * s).sum(-1, keepdims=True), 0.0)
    light = np.asarray(sun_color) * lambert + np.asarray(sky_ambient) * (0.6 + 0.4 * n[..., 1:2])
    return np.asarray(color, np.float64) * light
