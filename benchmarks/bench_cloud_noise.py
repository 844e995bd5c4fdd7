"""Detail noise of the ray-marched clouds: build time of the two textures at 128^3 / 32^3 (one run,
this machine; once per GPU context), the GPU against the float64 reference at 32^3 / 16^3, and pictures:
slices of every channel tiled 2×2 (``out/cloud_noise_base.png``, ``out/cloud_noise_detail.png``) and a
smooth cloud slice eroded with 0..3 octaves (``out/cloud_noise_erosion.png``).
``.venv/bin/python benchmarks/bench_cloud_noise.py``"""
from __future__ import annotations

import time

import numpy as np
from PIL import Image

from atmos import create_headless
from atmos.plugins.clouds.raymarch import noise_reference as ref
from atmos.plugins.clouds.raymarch.noise import DetailNoise


def grey(a: np.ndarray, zoom: int = 1) -> Image.Image:
    """[x, y] array in [0, 1] -> image (y down), nearest-neighbour zoom."""
    a = np.kron(np.clip(a.T, 0.0, 1.0), np.ones((zoom, zoom)))
    return Image.fromarray((a * 255).round().astype(np.uint8))


def erosion_picture(base, detail, scale: float = 1500.0, strength: float = 1.0) -> np.ndarray:
    """A vertical 1 km × 500 m slice through the top of a smooth lumpy cloud (density ramps over ~1.5
    to 3 cells of 40 m),
    eroded by detail_density with 0, 1, 2, 3 octaves, stacked top to bottom."""
    x, y = np.meshgrid(np.linspace(500, 1500, 400), np.linspace(1000, 500, 200), indexing="ij")
    r = np.hypot((x - 1000) / 800, (y - 450) / 350) + 0.15 * np.sin(x / 170) * np.cos(y / 130)
    d = np.clip((1.0 - r) * 6.0, 0.0, 1.0)
    p = np.stack([x, y + 700.0, np.full_like(x, 333.0)], -1)
    rows = [ref.detail_density(d, p, base, detail, o, scale, strength) for o in range(4)]
    return np.concatenate(rows, axis=1)


def main() -> None:
    gpu = create_headless((64, 64))
    info = gpu.info()
    start = time.perf_counter()
    noise = DetailNoise(gpu, 128, 32, seed=0)
    wall = time.perf_counter() - start
    again = DetailNoise(gpu, 128, 32, seed=0)
    print(f"{info.get('GL_RENDERER')}: build 128^3 + 32^3 = {noise.build_seconds * 1e3:.0f} ms "
          f"(first request {wall * 1e3:.0f} ms incl. compile; second request built={again.built})")
    base, detail = noise.read()
    grey(np.concatenate([np.tile(base[:, :, 40, c], (2, 2)) for c in range(4)], 0)).save("out/cloud_noise_base.png")
    grey(np.concatenate([np.tile(detail[:, :, 10, c], (2, 2)) for c in range(3)], 0), 4).save(
        "out/cloud_noise_detail.png")
    grey(erosion_picture(base, detail)).save("out/cloud_noise_erosion.png")
    small = DetailNoise(gpu, 32, 16, seed=11)
    b, d = small.read()
    t = time.perf_counter()
    rb, rd = ref.base_volume(32, 11), ref.detail_volume(16, 11)
    print(f"32^3/16^3: GPU vs float64 max |error| base {np.abs(b - rb).max() * 255:.3f}/255, "
          f"detail {np.abs(d - rd).max() * 255:.3f}/255 (reference {time.perf_counter() - t:.1f} s); "
          f"GPU build {small.build_seconds * 1e3:.0f} ms")
    for name, v in (("base", base), ("detail", detail)):
        print(name, "channel mean", v.mean(axis=(0, 1, 2)).round(3), "std", v.std(axis=(0, 1, 2)).round(3))
    gpu.release()


if __name__ == "__main__":
    main()
