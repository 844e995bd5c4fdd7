"""The diffusion field: the sun's scattered fluence in the cloud volume from a P1 (diffusion) solve on
the shading grid (halved per axis while it has more than :data:`FIELD_CELLS` cells: :func:`field_shape`), the renderers' multiple-scattering term beside the octaves (``clouds/volume/volume.glsl``
``cloud_diffusion``; weight ``CloudLightSettings.ms_diffusion``).

Per field cell (size ``cell`` metres, density ``rho``): sigma_t = sigma_t rho, scattering ss = albedo
sigma_t, absorption sa = (1 - albedo) sigma_t, transport extinction max(sa + ss (1 - g), FLOOR), D = 1 /
(3 transport extinction), air partly a vacuum (:func:`emptiness`); the once-scattered source Q0 = ss T (T: the shading volume's transmittance
toward the sun, unit irradiance) and its first moment Q1 = g ss T s (s = -sun_dir, the direction the
light travels). Finite volumes, cell-centred: harmonic face conductances A / (h / 2D0 + h / 2D1), Marshak
boundaries (no light enters from outside, ``A k / (2k + 1)``, k = 2D / h), the first-moment source as a
face flux 3 D_face Q1. The result (phi, F): collided fluence phi and flux F = -D grad phi + 3 D Q1
(``numpy.gradient``'s differences), |F| clamped to phi. The renderers' radiance from it toward a
view ray d is max(phi - 3 g F.d, -cos 2 H phi, 0) / 4pi (cos = d . sun, H the phase's
:attr:`atmos.phase.Phase.hemisphere_share`): against the sun never below what a lit surface sends
back, its outward hemisphere's light phi / 2pi scattered outward (the truncated P1 fell to 0 against the
flux at a lit surface; bench_cloud_light "sun behind", cumulus: no floor -17.8 %, -cos phi -9.1 %, now
+3.5 %).

:func:`diffusion_reference` solves the system in float64 by Jacobi-preconditioned conjugate
gradients in Chronopoulos and Gear's form (:func:`solve_cg`: both inner products of an iteration in one
reduction; the algorithm ``shaders/clouds/light/diffusion.comp`` runs in float32, one dispatch per
iteration: :class:`DiffusionSolver`, sliced over frames by :class:`DiffusionTask`).
Extinction is capped at :data:`SIGMA_MAX` (a millimetre's mean free path: opaque all the same) so no
float32 sum overflows.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from atmos.checks import check_int, check_num
from atmos.slicing import SliceTask
from atmos.gpu.context import GpuContext, require_gpu
from atmos.graph import TextureDesc
import atmos.plugins.clouds.light.grid as grid
from atmos.phase import Phase
from atmos.plugins.clouds.light.reference import multilinear
from atmos.plugins.clouds.light.shear_warp import check_volume_texture, groups, program
from atmos.gpu.uniforms import bind_images, bind_textures, buffer_uses, use_buffers, write_uniforms
from atmos.gpu.hazards import dispatch, dispatch_indirect
from atmos.gpu.block_table import BlockTable, ints

STEP_BINDING = 1        # diffusion.comp's Step block
FIELDS = 15             # diffusion.comp's per-cell vectors: x, p, r, s, w (two copies of each of the last three), the system

FLOOR = 1e-3               # 1/m: transport extinction floor (empty cells still conduct, finitely)
TOLERANCE = 1e-4           # relative residual |b - A phi| / |b| the GPU solve stops at
ITERATIONS = 300           # CG iterations per solve at most (the bench's grids converge in ~100, 32^3 in ~150)
WARM_ITERATIONS = 150      # at most, started from the last step's field (bench_cloud_field: sunset's 64x8x64 grid 75, cold 100)
FIELD_CELLS = 32768        # the field's grid: the shading grid, halved per axis until it has at most this many cells
DIFFUSION = "diffusion"    # the texture set's name for the field (rgba16f: phi, F)
SIGMA_MAX = 1e3            # 1/m: extinction cap (shaders/clouds/light/diffusion.comp has the same)
AIR_DEPTH = 1.0            # a cell's optical thickness sigma_t h below which it is partly air (:func:`emptiness`)


def emptiness(st, cell):
    """(e, h): a cell's emptiness e = clamp(1 - st h / AIR_DEPTH, 0, 1)^2 at extinction ``st`` (1/m) and
    the cells' mean size h (the cube root of their volume, metres). The system adds e / h of transport
    extinction and 3 e / 4h of absorption (the light that escapes): in air the diffusion length is then
    2h/3 and the flux into it phi/2, a vacuum (Marshak) boundary wherever the cloud's surface lies in the box."""
    h = float(np.prod(np.broadcast_to(np.asarray(cell, np.float64), (3,)))) ** (1.0 / 3.0)
    return np.clip(1.0 - np.asarray(st, np.float64) * h / AIR_DEPTH, 0.0, 1.0) ** 2, h


def diffusion_system(density, cell, sigma_t: float, albedo: float, g: float, T, sun_dir) -> dict:
    """The linear system A phi = b of the module docstring as arrays: ``diag``, ``rhs`` (cell volume
    units), ``faces`` (per axis the conductance between cells i and i+1), ``D``, ``q`` (g ss T: Q1 = q s)
    and ``s`` (the propagation direction)."""
    rho = np.asarray(density, np.float64)
    if rho.ndim != 3 or min(rho.shape) < 1:
        raise ValueError(f"density must be a 3D array with at least one cell per axis, got shape {rho.shape}")
    T = np.asarray(T, np.float64)
    if T.shape != rho.shape:
        raise ValueError(f"T must have the density's shape {rho.shape}, got {T.shape}")
    cell = np.broadcast_to(np.asarray(cell, np.float64), (3,))
    st = np.minimum(sigma_t * np.maximum(np.nan_to_num(rho), 0.0), SIGMA_MAX)
    ss, sa = albedo * st, (1.0 - albedo) * st
    e, hm = emptiness(st, cell)
    D = 1.0 / (3.0 * np.maximum(sa + ss * (1.0 - g) + e / hm, FLOOR))
    T = np.clip(np.nan_to_num(T), 0.0, 1.0)
    s = -np.asarray(sun_dir, np.float64) / np.linalg.norm(sun_dir)
    q = g * ss * T
    V = cell.prod()
    diag, rhs = (sa + 0.75 * e / hm) * V, ss * T * V
    faces = []
    for a in range(3):
        A, h = V / cell[a], cell[a]
        lo, hi = _sides(a, slice(0, -1)), _sides(a, slice(1, None))
        G = A / (h / (2 * D[lo]) + h / (2 * D[hi]))
        Df = 2 * D[lo] * D[hi] / (D[lo] + D[hi])
        flux = A * 3 * Df * 0.5 * (q[lo] + q[hi]) * s[a]         # from cell i to i+1 by the source
        diag[lo] += G; diag[hi] += G
        rhs[lo] -= flux; rhs[hi] += flux
        faces.append(G)
        for side, n in ((slice(0, 1), -1.0), (slice(-1, None), 1.0)):   # Marshak boundary faces
            b = _sides(a, side)
            k = 2 * D[b] / h
            diag[b] += A * k / (2 * k + 1)
            rhs[b] -= A * 3 * D[b] * q[b] * s[a] * n / (2 * k + 1)
    return {"diag": diag, "rhs": rhs, "faces": faces, "D": D, "q": q, "s": s, "cell": cell}


def _sides(axis: int, part: slice) -> tuple:
    sl = [slice(None)] * 3
    sl[axis] = part
    return tuple(sl)


def apply(system: dict, x: np.ndarray) -> np.ndarray:
    """A x."""
    y = system["diag"] * x
    for a, G in enumerate(system["faces"]):
        lo, hi = _sides(a, slice(0, -1)), _sides(a, slice(1, None))
        y[lo] -= G * x[hi]
        y[hi] -= G * x[lo]
    return y


def relative_residual(system: dict, x) -> float:
    """|b - A x| / |b| (0 when b = 0 and x = 0)."""
    b = system["rhs"]
    r = np.sqrt(((b - apply(system, np.asarray(x, np.float64))) ** 2).sum())
    bn = np.sqrt((b ** 2).sum())
    return float(r / bn) if bn > 0 else float(r)


def solve_cg(system: dict, x0=None, tol: float = 1e-10, iterations: int = 20000):
    """Jacobi-preconditioned conjugate gradients from ``x0`` (zeros) until |r| <= tol |b|:
    (x, iterations run). Chronopoulos and Gear's form (1989), as the shader runs it: u = r / diag and
    w = A u are carried, s = A p follows p by recurrence, and an iteration's two inner products
    gamma = (r, u), delta = (w, u) (and |r|^2, for the stop) are summed together; a step that would
    not descend (a non-positive denominator) is 0."""
    diag, b = system["diag"], system["rhs"]
    x = np.zeros_like(b) if x0 is None else np.array(x0, np.float64)
    r = b - apply(system, x)
    u = r / diag
    w = apply(system, u)
    limit = tol * tol * (b ** 2).sum()
    p = s = None
    gamma_old = alpha_old = 0.0
    for it in range(iterations):
        gamma, delta, rr = (r * u).sum(), (w * u).sum(), (r * r).sum()
        if rr <= limit:
            return x, it
        beta, denom = 0.0, delta
        if p is not None:
            beta = gamma / gamma_old if gamma_old > 0 else 0.0
            if alpha_old > 0:
                denom = delta - beta * gamma / alpha_old
        alpha = gamma / denom if denom > 0 else 0.0
        p = u if p is None else u + beta * p
        s = w if s is None else w + beta * s
        x = x + alpha * p
        r = r - alpha * s
        u = r / diag
        w = apply(system, u)
        gamma_old, alpha_old = gamma, alpha
    return x, iterations


def field(system: dict, phi) -> np.ndarray:
    """(nx, ny, nz, 4): (phi, F) of a solution ``phi`` (F = -D grad phi + 3 D Q1, |F| <= max(phi, 0))."""
    phi = np.asarray(phi, np.float64)
    D, cell = system["D"], system["cell"]
    grads = [np.gradient(phi, cell[a], axis=a) if phi.shape[a] > 1 else np.zeros_like(phi) for a in range(3)]
    F = -D[..., None] * np.stack(grads, -1) + 3 * (D * system["q"])[..., None] * system["s"]
    n = np.linalg.norm(F, axis=-1, keepdims=True)
    F = F * np.minimum(1.0, np.maximum(phi, 0)[..., None] / np.maximum(n, 1e-300))
    return np.concatenate([phi[..., None], F], -1)


def diffusion_reference(density, cell, sigma_t: float, albedo: float, g: float, T, sun_dir,
                        tol: float = 1e-10) -> np.ndarray:
    """float64 (nx, ny, nz, 4): the field (phi, F) for unit sun irradiance; ``density`` and ``T`` on
    the field's grid (:func:`resample` of the fine density and the shading grid's T to
    :func:`field_shape`), ``cell`` its cell size in metres."""
    system = diffusion_system(density, cell, sigma_t, albedo, g, T, sun_dir)
    return field(system, solve_cg(system, tol=tol)[0])


def field_shape(shading_shape) -> tuple[int, int, int]:
    """The field's grid over the volume's box: ``shading_shape`` with ceil(n / f) cells per axis, f the
    smallest of 1, 2, 4, ... leaving at most :data:`FIELD_CELLS` (the field is smooth; the solve's cost
    grows like cells^(4/3))."""
    f = 1
    while np.prod([-(-int(n) // f) for n in shading_shape]) > FIELD_CELLS:
        f *= 2
    return tuple(-(-int(n) // f) for n in shading_shape)


def resample(volume, shape) -> np.ndarray:
    """``volume`` sampled trilinearly (clamped) at the cell centres of a grid of ``shape`` over the same
    box (what the GPU solve reads from the density and transmittance textures)."""
    v = np.asarray(volume, np.float64)
    h = np.array(v.shape) / np.array(shape)
    p = np.stack(np.meshgrid(*[(np.arange(m) + 0.5) * h[a] - 0.5 for a, m in enumerate(shape)], indexing="ij"), -1)
    return multilinear(v, p)


def diffusion_radiance(field_volume, uvw, dirs, lobes, sun_dir) -> np.ndarray:
    """:func:`field_radiance` at texture coordinates ``uvw`` (..., 3) for view rays ``dirs``
    (..., 3, unit, toward the eye's travel): trilinear (clamp to edge) like the renderers' fetch."""
    f = np.asarray(field_volume, np.float64)
    p = np.asarray(uvw, np.float64) * np.array(f.shape[:3]) - 0.5
    return field_radiance(np.stack([multilinear(f[..., k], p) for k in range(4)], -1), dirs, lobes, sun_dir)


def field_radiance(values, dirs, lobes, sun_dir) -> np.ndarray:
    """max(phi - 3 g F.d, -cos 2 H phi, 0) / 4pi of field values ``values`` (..., 4) = (phi, F) for view
    rays ``dirs`` (unit; cos = d . ``sun_dir``, unit, toward the sun), ``lobes`` = (g, g2, w) the phase's
    (g its mean cosine, H its :attr:`~atmos.phase.Phase.hemisphere_share`): against the sun never below
    what a lit surface sends back, its outward hemisphere's light phi / 2pi scattered outward."""
    g, share = Phase(*lobes).mean_cosine, Phase(*lobes).hemisphere_share
    v, d = np.asarray(values, np.float64), np.asarray(dirs, np.float64)
    c = (d * np.asarray(sun_dir, np.float64)).sum(-1)
    p1 = v[..., 0] - 3 * g * (v[..., 1:] * d).sum(-1)
    return np.maximum(np.maximum(p1, -c * 2 * share * v[..., 0]), 0.0) / (4 * math.pi)


def diffusion_desc(shape, scale: int) -> TextureDesc:
    """The texture of a set's field for a density of ``shape`` at shading ``scale`` (rgba16f: phi, F;
    :func:`field_shape`)."""
    return TextureDesc(field_shape(grid.shading_shape(shape, scale)), 4, "f2")


class DiffusionSolver:
    """GPU field on :func:`field_shape`'s grid: :meth:`begin` assembles the system from a fine density
    texture and the shading grid's transmittance texture (both sampled trilinearly at its cell centres) (and takes the last solve's phi as the start unless ``warm=False``),
    :meth:`iterate` runs CG iterations (they do nothing once |r| <= ``tolerance`` |b|), :meth:`write`
    stores (phi, F) into a :func:`diffusion_desc` texture; :meth:`solve` does all three."""

    def __init__(self, gpu: GpuContext, shape, scale: int = 1, tolerance: float = TOLERANCE):
        self.gpu = require_gpu(gpu)
        self.shape = tuple(int(n) for n in shape)
        self.scale = grid.check_scale(scale)
        self.tolerance = check_num("DiffusionSolver", "tolerance", tolerance, 1e-7, 1.0)
        self.shading_shape = grid.shading_shape(self.shape, self.scale)
        self.field_shape = field_shape(self.shading_shape)
        self.cells = int(np.prod(self.field_shape))
        self.groups = groups(self.cells, 256)
        ctx = self.gpu.ctx
        self._cells = ctx.buffer(reserve=FIELDS * 4 * self.cells)
        self._cells.clear()
        self._parts = ctx.buffer(reserve=(7 * self.groups + 4) * 4)
        self._parts.clear()
        self._args = ctx.buffer(np.array([self.groups, 1, 1], np.uint32).tobytes())
        self._steps = BlockTable(self.gpu, STEP_BINDING, [ints(stage, cur, first) for stage, cur, first
                                                          in itertools.product(range(5), (0, 1), (0, 1))])
        self._program = program(self.gpu, "diffusion")    # the context's cached program, for its lifetime
        self._buffers = buffer_uses(self._program, {"Cells": self._cells, "Parts": self._parts, "Args": self._args})
        self._cur = 0
        self._first = True
        self.iterations = 0          # run since the last begin (each does nothing once converged)

    def _dispatch(self, stage: int, **values) -> None:
        """Stage 3 (the iteration) runs indirect: no groups once converged. The stage and the
        iteration's state come from the Step block's record (stage, cur, first): no uniform writes."""
        prog = self._program
        if values:
            write_uniforms(prog, values)
        self._steps.use(4 * stage + 2 * self._cur + int(self._first))
        use_buffers(prog, self._buffers)
        if stage == 3:
            dispatch_indirect(prog, self._args)
        else:
            dispatch(prog, self.groups)

    def begin(self, density, transmittance, sigma_t: float, albedo: float, g: float, cell, sun_dir,
              warm: bool = True) -> None:
        check_volume_texture(density, self.shape, "density")
        check_volume_texture(transmittance, self.shading_shape, "transmittance")
        sun = np.asarray(sun_dir, np.float64)
        n = np.linalg.norm(sun)
        if sun.shape != (3,) or not (np.isfinite(n) and n > 0):
            raise ValueError(f"sun_dir must be a finite nonzero 3-vector, got {sun_dir!r}")
        coarse = np.asarray(cell, np.float64) * np.array(self.shape) / np.array(self.field_shape)
        bind_textures(self._program, fine=density, trans=transmittance)
        self._cur, self._first, self.iterations = 0, True, 0
        self._args.write(np.array([self.groups, 1, 1], np.uint32).tobytes())
        common = {"fine_size": self.shape, "trans_size": self.shading_shape,
                  "size": self.field_shape,
                  "sigma_t": float(sigma_t), "albedo": float(albedo), "g": float(g), "tolerance": self.tolerance,
                  "cell": tuple(float(v) for v in coarse), "s": tuple(float(v) for v in -sun / n)}
        self._dispatch(0, cold=int(not warm), **common)
        self._dispatch(1)
        self._dispatch(2)

    def iterate(self, count: int) -> None:
        """``count`` iterations (stage 3, one dispatch each, as :meth:`_dispatch`): the buffers are bound
        by the first dispatch and stay bound; each dispatch still declares their uses (its barrier)."""
        prog, steps, args, uses = self._program, self._steps, self._args, self._buffers
        bind = True
        for _ in range(int(count)):
            steps.use(4 * 3 + 2 * self._cur + int(self._first))
            use_buffers(prog, uses, bind)
            bind = False
            dispatch_indirect(prog, args)
            self._cur, self._first = 1 - self._cur, False
            self.iterations += 1

    def write(self, target) -> None:
        size = tuple(getattr(target, "size", ()))
        if size != self.field_shape or getattr(target, "components", 0) != 4 or getattr(target, "dtype", "") != "f2":
            raise ValueError(f"target must be a 4-component f2 3D texture of size {self.field_shape} "
                             f"(diffusion_desc); got {target!r}")
        bind_images(self._program, target=target)
        self._dispatch(4)

    def solve(self, density, transmittance, target, *medium, iterations: int = ITERATIONS, warm: bool = True) -> None:
        """:meth:`begin` (``medium``: sigma_t, albedo, g, cell, sun_dir), ``iterations``, :meth:`write`."""
        self.begin(density, transmittance, *medium, warm=warm)
        self.iterate(iterations)
        self.write(target)

    def relative_residual(self) -> float:
        """|r| / |b| after the iterations run (reads the partial sums back: a diagnostic)."""
        parts = np.frombuffer(self._parts.read(), np.float32).astype(np.float64)[:7 * self.groups]
        parts = parts.reshape(7, self.groups)
        rr, bb = parts[4 + self._cur].sum(), parts[6].sum()
        return float(math.sqrt(rr / bb)) if bb > 0 else math.sqrt(rr)

    def release(self) -> None:
        for buf in (self._cells, self._parts, self._args):
            if buf is not None:
                buf.release()
        self._cells = self._parts = self._args = None
        self._steps.release()


class DiffusionTask(SliceTask):
    """The cloud chain's field task, after the shading, in the steps whose :meth:`plan` found it
    ``wanted()`` (a renderer reads it: :class:`~atmos.plugins.clouds.volume.field_demand.FieldDemand`):
    ``slices`` job slices of set C (assembly and the first iterations, more iterations, the last also
    writes ``set[DIFFUSION]``), ``iterations`` in all. Other steps run no slice and leave C without a
    field; the solver and a set's field texture are made on the first step that wants them. A set shaded
    outside a sliced job (static clouds) takes its whole field at once with :meth:`solve`.
    ``medium`` is a zero-argument callable giving (sigma_t, albedo, g, cell, sun_dir), read when a
    step's field begins; the solve starts from the last solve's phi (warm: at most ``warm_iterations``,
    fewer dispatches once converged; ``benchmarks/bench_cloud_field.py``)."""

    def __init__(self, gpu: GpuContext, shape, scale: int, medium, wanted=lambda: True, slices: int = 8,
                 iterations: int = ITERATIONS, warm_iterations: int = WARM_ITERATIONS, density: str = "density",
                 transmittance: str = "transmittance", name: str = "diffusion"):
        self.gpu, self.shape, self.scale = gpu, tuple(shape), grid.check_scale(scale)
        self.medium, self.wanted = medium, wanted
        self.cold = check_int("DiffusionTask", "iterations", iterations, 1, 100000)
        self.warm = min(self.cold, check_int("DiffusionTask", "warm_iterations", warm_iterations, 1, 100000))
        self.total = self.cold             # this step's iterations
        self.density, self.transmittance = density, transmittance
        self.solver: DiffusionSolver | None = None
        self.active = False            # whether the step in progress solves the field
        n = check_int("DiffusionTask", "slices", slices, 1, 1000)
        super().__init__(name, lambda: n if self.active else 0, self._run)

    def plan(self, target) -> None:
        """At the start of a step into ``target`` (before its slices are counted): solve it if wanted,
        else take the set's field away (no renderer reads a stale one)."""
        self.active = bool(self.wanted())
        if not self.active:
            target.drop(DIFFUSION)
            return
        self.total = self.warm if self.solver is not None else self.cold
        if self.solver is None:
            self.solver = DiffusionSolver(self.gpu, self.shape, self.scale)
        target.ensure(self.gpu, DIFFUSION, diffusion_desc(self.shape, self.scale))

    def solve(self, target) -> None:
        """:meth:`plan` and, if wanted, every slice of ``target``'s field now."""
        self.plan(target)
        if self.active:
            n = self.count()
            for index in range(n):
                self._slice(index, n, target)

    def _run(self, index: int, job) -> None:
        self._slice(index, job.slices, job.target)

    def _slice(self, index: int, n: int, target) -> None:
        if index == 0:
            self.solver.begin(target[self.density], target[self.transmittance], *self.medium())
        self.solver.iterate(self.total * (index + 1) // n - self.total * index // n)
        if index == n - 1:
            self.solver.write(target[DIFFUSION])

    def release(self) -> None:
        if self.solver is not None:
            self.solver.release()
            self.solver = None


def field_medium(cloud_settings, sun_dir) -> tuple:
    """(sigma_t, albedo, g_mean, cell_size, sun_dir): what :meth:`DiffusionSolver.begin` takes, from a
    ``CloudSettings`` medium."""
    s = cloud_settings
    return (float(s.sigma_t), float(s.albedo), s.phase.mean_cosine,
            tuple(s.cell_size), tuple(float(v) for v in sun_dir))


def read_field(texture) -> np.ndarray:
    """float64 (nx, ny, nz, 4) of a :func:`diffusion_desc` texture (reads it back: tests, diagnostics)."""
    nx, ny, nz = texture.size
    return np.frombuffer(texture.read(), np.float16).reshape(nz, ny, nx, 4).transpose(2, 1, 0, 3).astype(np.float64)
