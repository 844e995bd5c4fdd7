"""The project's path tracer (``plugins/clouds/light/path_tracer.py``) against an independent one,
Mitsuba 3 (an optional benchmark dependency: ``pip install eradiate-mitsuba``, or the ``bench`` extra;
without it this script says so and exits with status 2).

Method. Both tracers get the same rays (the tracer's :func:`camera_rays`: pixel centres) and the same
scene. On Mitsuba's side (``llvm_ad_rgb``, the ``volpath`` integrator driven ray by ray through
``integrator.sample``):

- the medium: a ``heterogeneous`` medium whose ``sigma_t`` is a ``gridvolume`` of the density (array
  transposed to Mitsuba's [z, y, x] order), ``scale`` = sigma_t, constant ``albedo``; the gridvolume's
  ``to_world`` maps its unit cube onto the box ``[lo, lo + shape * cell]``. Its texel centres sit at
  ``(i + 0.5) / n`` with trilinear filtering and clamped lookups, which is the tracer's "trilinear
  between cell centres, edge held out to the faces"; a ``cube`` with a ``null`` BSDF holds it;
- the phase: ``hg`` (one lobe); two lobes as a ``tabphase`` of ``(1 - w) HG(g) + w HG(g2)`` on 8,193
  cosines (linear between them: ≤ 1e-3 relative at the forward peak of g = 0.85). Mitsuba's
  ``blendphase`` (``--blendphase``) is biased here: its ``sample`` returns the chosen lobe's pdf, not
  the blend's, and the MIS weights of environment hits use it (the environment's single scattering
  in a thin slab seen from the side: blendphase 28.67 against 26.99 for 0.9 × its hg(0.85) image +
  0.1 × its hg(−0.3) image; the tracer's two-lobe image 27.02 against 26.99);
- the sun: a ``directional`` emitter, ``irradiance`` = the sun's, travelling along ``-sun_dir``;
- the environment: an ``envmap`` from a lat-long bitmap (1024 rows: the top half the sky, the bottom
  half the ground; Mitsuba's envmap is y-up with row 0 at the zenith); its bilinear lookup blurs the
  horizon over ±1 row (±0.18°), a negligible band for these scenes;
- radiance scattered toward the eye only: ``hide_emitters`` drops the environment that a camera ray
  sees straight through the medium (the sun, a delta light, is never seen), so the render is the
  tracer's premultiplied radiance with no subtraction;
- transmittance: a second render of the same medium with albedo 0, no sun and a constant environment
  of radiance 1, emitters shown: each sample is 1 if the primary ray crossed unabsorbed (delta
  tracking), so its mean is T;
- the cameras sit a few millimetres off the volume's symmetry planes: a ray that leaves the box
  exactly through an edge of the cube (a square image centred on a cube's axis has some) never
  escapes Mitsuba's cube in float32 (T = 0 there, found at 24×24; the tracer gives T = 1);
- orders: the tracer's ``max_order = k`` is ``max_depth = k + 1`` (checked here on a thin slab).

Per case: the image-sum bias of the project against Mitsuba (%) with its standard error, the
relative RMSE over pixels (RMSE / mean Mitsuba radiance) beside the RMSE the two estimates' noise
alone would give, the same for 1 − T over the pixels that see the volume, and each side's seconds
(CPU). The trivial cases run first (a thin homogeneous slab: single scattering, orders ≤ 2, sky and
ground alone, all orders; transmittance in each); ``--check``: only them, ``--no-check``: without.

    python benchmarks/bench_path_tracer_mitsuba.py [--size 32 32] [--spp 256] [--mi-spp 1024] [--check | --no-check]

The table in benchmarks/README.md: --spp 2048 --mi-spp 8192.
"""
from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from atmos.plugins.clouds.light.path_tracer import camera_rays, trace

try:
    import mitsuba as mi
except ImportError:                                  # pragma: no cover - optional dependency
    mi = None

SUN_EL = 30.0
SUN_DIR = np.array([math.cos(math.radians(SUN_EL)), math.sin(math.radians(SUN_EL)), 0.0])  # toward the sun (+x)
SUN_E = np.array([3.0, 2.8, 2.6])
SKY = np.array([0.25, 0.35, 0.55])
GROUND = np.array([0.08, 0.07, 0.06])


# -- volumes ---------------------------------------------------------------------------------------

def blob(n=20, cell=1.0):
    """A smooth Gaussian blob n³ cells, centred at the origin, density 1 at its centre."""
    c = (np.arange(n) + 0.5) - n / 2
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    r2 = (x ** 2 + (1.4 * y) ** 2 + (0.8 * z) ** 2) / (n / 4.5) ** 2
    density = np.exp(-r2)
    return density, (cell,) * 3, (-n * cell / 2,) * 3


def slab(nx=16, ny=4, nz=16, cell=1.0, smooth=True):
    """A slab nx × ny × nz cells (homogeneous, or with a smooth bump in density)."""
    density = np.ones((nx, ny, nz))
    if smooth:
        c = (np.arange(nx) + 0.5) / nx - 0.5
        density *= (0.6 + 0.4 * np.cos(2 * math.pi * c))[:, None, None] * np.linspace(0.7, 1.0, ny)[None, :, None]
    return density, (cell,) * 3, (-nx * cell / 2, -ny * cell / 2, -nz * cell / 2)


OFFSET = np.array([0.0137, 0.0071, 0.0093])   # off the volume's symmetry planes (see the module docstring)


def view(name, extent):
    """(position, forward, up, fov) of the named view of a volume about the origin of size ``extent``."""
    d = 2.2 * extent
    if name == "side":
        p, f, u = (0.0, 0.0, -d), (0, 0, 1), (0, 1, 0)
    elif name == "below":
        p, f, u = (0.0, -d, 0.3), (0, 1, -0.3 / d), (0, 0, 1)
    elif name == "toward_sun":       # the camera on the far side from the sun, looking at it through the cloud
        p, f, u = -SUN_DIR * d, SUN_DIR, (0, 1, 0)
    else:
        raise ValueError(name)
    return tuple(np.asarray(p, float) + OFFSET), tuple(f), u, 40.0


# -- the Mitsuba scene -----------------------------------------------------------------------------

def env_bitmap(sky, ground, rows=1024, cols=8):
    img = np.empty((rows, cols, 3), np.float32)
    img[: rows // 2] = sky
    img[rows // 2:] = ground
    return mi.Bitmap(img)


def hg(cos, g):
    return (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * cos) ** 1.5)


BLENDPHASE = False


def mi_scene(density, cell, lo, *, sigma_t, albedo, g, g2=0.0, w=0.0, sun=True, env=True,
             transmittance=False, max_depth=-1):
    """(scene, integrator) for Mitsuba; ``transmittance``: albedo 0, no sun, a constant environment 1, shown."""
    density = np.asarray(density, np.float64)
    shape = np.array(density.shape, float)
    lo = np.asarray(lo, float)
    size = shape * np.asarray(cell, float)
    grid = mi.VolumeGrid(np.ascontiguousarray(density.transpose(2, 1, 0)[..., None], np.float32))
    to_world = mi.ScalarTransform4f.translate(mi.ScalarPoint3f(*lo)) @ mi.ScalarTransform4f.scale(
        mi.ScalarPoint3f(*size))
    if w > 0 and not BLENDPHASE:
        c = np.linspace(-1.0, 1.0, 8193)             # cos of the scattering angle, -1 backward .. 1 forward
        ph = {"type": "tabphase", "values": ", ".join(f"{v:.9g}" for v in (1 - w) * hg(c, g) + w * hg(c, g2))}
    elif w > 0:
        ph = {"type": "blendphase", "weight": float(w), "phase1": {"type": "hg", "g": float(g)},
              "phase2": {"type": "hg", "g": float(g2)}}
    else:
        ph = {"type": "hg", "g": float(g)}
    medium = {"type": "heterogeneous", "albedo": 0.0 if transmittance else float(albedo),
              "sigma_t": {"type": "gridvolume", "grid": grid, "to_world": to_world,
                          "filter_type": "trilinear", "wrap_mode": "clamp"},
              "scale": float(sigma_t), "phase": ph}
    centre = lo + size / 2
    cube = {"type": "cube", "bsdf": {"type": "null"}, "interior": medium,
            "to_world": mi.ScalarTransform4f.translate(mi.ScalarPoint3f(*centre)) @ mi.ScalarTransform4f.scale(
                mi.ScalarPoint3f(*(size / 2)))}
    scene = {"type": "scene", "cube": cube}
    if transmittance:
        scene["env"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    else:
        if env:
            scene["env"] = {"type": "envmap", "bitmap": env_bitmap(SKY, GROUND)}
        if sun:
            scene["sun"] = {"type": "directional", "direction": mi.ScalarVector3f(*(-SUN_DIR)),
                            "irradiance": {"type": "rgb", "value": SUN_E.tolist()}}
    integrator = mi.load_dict({"type": "volpath", "max_depth": int(max_depth), "rr_depth": 20,
                               "hide_emitters": not transmittance})
    return mi.load_dict(scene), integrator


def mi_trace(scene, integrator, origins, dirs, spp, seed=0, wave=1 << 18):
    """Per ray: mean radiance (n, 3) and its standard error, over ``spp`` samples, through ``integrator.sample``."""
    n = len(origins)
    per = max(1, min(spp, wave // n))
    s1, s2 = np.zeros((n, 3)), np.zeros((n, 3))
    done, k = 0, 0
    sampler = mi.load_dict({"type": "independent"})
    while done < spp:
        m = min(per, spp - done)
        o = np.repeat(origins, m, 0).astype(np.float32)
        d = np.repeat(dirs, m, 0).astype(np.float32)
        sampler.seed(seed * 7919 + k, n * m)
        ray = mi.Ray3f(mi.Point3f(o[:, 0], o[:, 1], o[:, 2]), mi.Vector3f(d[:, 0], d[:, 1], d[:, 2]))
        spec, _, _ = integrator.sample(scene, sampler, ray, None, True)
        v = np.array(spec, np.float64)
        v = (v.T if v.shape[0] == 3 and v.shape[-1] != 3 else v).reshape(n, m, 3)
        s1 += v.sum(1)
        s2 += (v * v).sum(1)
        done += m
        k += 1
    mean = s1 / spp
    var = np.maximum(s2 / spp - mean ** 2, 0.0)
    return mean, np.sqrt(var / max(spp - 1, 1))


# -- comparison ------------------------------------------------------------------------------------

def compare(p, pe, m, me):
    """bias % (and its standard error), rel. RMSE %, the RMSE noise alone would give %."""
    sp, sm = p.sum(), m.sum()
    bias = (sp - sm) / sm
    bias_se = math.sqrt((pe ** 2).sum() + (me ** 2).sum()) / sm
    mean = m.mean()
    rmse = math.sqrt(((p - m) ** 2).mean()) / mean
    noise = math.sqrt((pe ** 2 + me ** 2).mean()) / mean
    return 100 * bias, 100 * bias_se, 100 * rmse, 100 * noise


def run_case(name, vol, medium, cam, size, spp, mi_spp, max_order=None, rows=None, seed=1, sun=True):
    density, cell, lo = vol
    pos, fwd, up, fov = cam
    o, d = camera_rays(pos, fwd, up, fov, size)
    t0 = time.perf_counter()
    r = trace(density, cell, lo, o, d, sun_dir=SUN_DIR, sun_irradiance=SUN_E if sun else 0.0, sky=SKY, ground=GROUND,
              samples=spp, max_order=max_order, rng=np.random.default_rng(seed), **medium)
    tp = time.perf_counter() - t0
    md = -1 if max_order is None else max_order + 1
    t0 = time.perf_counter()
    sc, it = mi_scene(density, cell, lo, max_depth=md, sun=sun, **medium)
    ml, mle = mi_trace(sc, it, o, d, mi_spp, seed=seed)
    sc, it = mi_scene(density, cell, lo, transmittance=True, **medium)
    mt, mte = mi_trace(sc, it, o, d, mi_spp, seed=seed + 100)
    tm = time.perf_counter() - t0
    mt, mte = mt[:, 0], mte[:, 0]
    b, bse, rm, nz = compare(r.radiance, r.radiance_error, ml, mle)
    hit = mt < 0.999
    tb, tbse, trm, tnz = compare(1 - r.transmittance[hit], r.transmittance_error[hit], 1 - mt[hit], mte[hit])
    row = dict(case=name, bias=b, bias_se=bse, rmse=rm, noise=nz, tbias=tb, tbias_se=tbse, trmse=trm, tnoise=tnz,
               t_project=tp, t_mitsuba=tm, mean_rad=float(ml.mean()))
    print(f"| {name} | {b:+.2f} ± {bse:.2f} | {rm:.2f} ({nz:.2f}) | {tb:+.2f} ± {tbse:.2f} | {trm:.2f} ({tnz:.2f}) "
          f"| {tp:.1f} | {tm:.1f} |", flush=True)
    if rows is not None:
        rows.append(row)
    return row


HEADER = ("| case | radiance bias % (± s.e.) | rel. RMSE % (noise alone) | 1 − T bias % (± s.e.) "
          "| 1 − T rel. RMSE % (noise) | project s | Mitsuba s |\n|---|---|---|---|---|---|---|")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, nargs=2, default=(32, 32), metavar=("W", "H"))
    ap.add_argument("--spp", type=int, default=256, help="the project tracer's paths per pixel")
    ap.add_argument("--mi-spp", type=int, default=1024, help="Mitsuba's samples per pixel")
    ap.add_argument("--check", action="store_true", help="only the trivial cases (thin homogeneous slab)")
    ap.add_argument("--no-check", action="store_true", help="skip the trivial cases")
    ap.add_argument("--cases", nargs="*", help="only these cases of the full-order set")
    ap.add_argument("--blendphase", action="store_true", help="two lobes as Mitsuba's blendphase (biased; docstring)")
    a = ap.parse_args(argv)
    if mi is None:
        print("Mitsuba 3 is not installed: pip install eradiate-mitsuba (or the project's 'bench' extra); skipped.")
        return 2
    mi.set_variant("llvm_ad_rgb")
    global BLENDPHASE
    BLENDPHASE = a.blendphase
    size = tuple(a.size)
    rows = []
    print(f"{size[0]}×{size[1]}, project {a.spp} spp, Mitsuba {a.mi_spp} spp, sun {SUN_EL}° up\n")
    print(HEADER)
    if not a.no_check:
        thin = slab(16, 4, 16, smooth=False)
        med = dict(sigma_t=0.25, albedo=0.9, g=0.5)          # tau 1 through the slab's 4 m
        run_case("check: thin slab, side, single scattering", thin, med, view("side", 16), size, a.spp, a.mi_spp,
                 max_order=1, rows=rows)
        run_case("check: thin slab, below, single scattering", thin, med, view("below", 16), size, a.spp, a.mi_spp,
                 max_order=1, rows=rows)
        run_case("check: thin slab, below, orders ≤ 2", thin, med, view("below", 16), size, a.spp, a.mi_spp,
                 max_order=2, rows=rows)
        run_case("check: thin slab, below, sky and ground only, single scattering", thin, med, view("below", 16),
                 size, a.spp, a.mi_spp, max_order=1, rows=rows, sun=False)
        run_case("check: thin slab, side, sky and ground only, all orders", thin, med, view("side", 16),
                 size, a.spp, a.mi_spp, rows=rows, sun=False)
        run_case("check: thin slab, side, all orders", thin, med, view("side", 16), size, a.spp, a.mi_spp,
                 rows=rows)
        if a.check:
            return 0
    b = blob(20)
    s = slab(16, 4, 16)
    hg = dict(sigma_t=1.2, albedo=0.99, g=0.8)          # blob: tau ≈ 12 through the centre along x
    two = dict(sigma_t=1.2, albedo=0.99, g=0.85, g2=-0.3, w=0.1)
    shg = dict(sigma_t=2.5, albedo=0.99, g=0.8)          # slab: tau ≈ 8.5 vertically at the middle
    cases = [
        ("blob, HG 0.8, side", b, hg, view("side", 20)),
        ("blob, HG 0.8, below", b, hg, view("below", 20)),
        ("blob, HG 0.8, toward the sun", b, hg, view("toward_sun", 20)),
        ("blob, two lobes (0.85, −0.3, 0.1), side", b, two, view("side", 20)),
        ("blob, two lobes, side, Mitsuba's blendphase (biased)", b, two, view("side", 20), True),
        ("slab, HG 0.8, side", s, shg, view("side", 16)),
        ("slab, HG 0.8, below", s, shg, view("below", 16)),
        ("slab, HG 0.8, toward the sun", s, shg, view("toward_sun", 16)),
    ]
    for name, vol, med, cam, *blend in cases:
        if a.cases and not any(c in name for c in a.cases):
            continue
        BLENDPHASE = a.blendphase or bool(blend)
        run_case(name, vol, med, cam, size, a.spp, a.mi_spp, rows=rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
