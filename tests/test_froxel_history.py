"""atmos.froxels.FroxelHistory: a froxel volume's jittered slices averaged over frames through reprojection
(shaders/core/froxel_history.comp) against its float64 twin history_reference, and through the light
shafts: a still view converges to the mean of the jittered volumes; a view that skips a frame or changes
its volume restarts from the fresh one."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from atmos.camera import Camera, view_basis
from atmos.frame_constants import bind_frame
from atmos.froxels import FroxelHistory, froxel_jitter, froxel_knee, history_reference
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.lighting import Sun

F16 = 2.0 ** -11          # rgba16f's relative rounding


class HistoryFrame:
    """What FroxelHistory.resolve uses of a graph frame: the view (camera, aspect, clock) and dispatch."""

    def __init__(self, gpu, camera: Camera, size, index: int):
        self.view = SimpleNamespace(camera=camera, aspect=size[0] / size[1], clock=SimpleNamespace(frame=index))
        bind_frame(gpu, camera, Sun(), size)

    def dispatch(self, program, groups, textures=None, images=None, buffers=None) -> None:
        bind_textures(program, textures or {})
        bind_images(program, images or {})
        dispatch(program, *groups)


def volume_texture(ctx, volume: np.ndarray):
    """An rgba16f 3D texture of ``volume`` (W, H, L, 4), and the float64 values it holds."""
    w, h, layers = volume.shape[:3]
    data = volume.astype(np.float16)
    tex = ctx.texture3d((w, h, layers), 4, data.transpose(2, 1, 0, 3).tobytes(), dtype="f2")
    return tex, data.astype(np.float64)


def smooth_volume(rng, shape) -> np.ndarray:
    """Random (W, H, L, 4) values in (0, 2) that vary over a few texels (a medium's sums do)."""
    x, y, z = np.meshgrid(*(np.linspace(0.0, 1.0, n) for n in shape), indexing="ij")
    out = np.empty((*shape, 4))
    for c in range(4):
        f = rng.uniform(1.0, 4.0, 3)
        out[..., c] = 1.0 + 0.9 * np.sin(f[0] * x * 6.3 + f[1] * y * 6.3 + f[2] * z * 3.1 + rng.uniform(0, 6.3))
    return out


def test_froxel_history_matches_its_float64_twin(gpu, rng, filter_bits):
    """A random volume resolved once (no history: itself, bit for bit), then a second one over it from a
    camera moved a few metres and turned a few degrees: history_reference's blend at every froxel, within
    the output's f2 rounding and the history read's trilinear weights (filter_bits), froxels whose previous
    point lies within 1e-4 of the old view's edge left out (float32 decides those either way)."""
    gpu.make_current()
    shape = (int(rng.integers(6, 20)), int(rng.integers(4, 12)), int(rng.integers(3, 24)))
    range_ = float(rng.uniform(500.0, 8000.0))
    knee = froxel_knee(range_)
    aspect = shape[0] / shape[1]
    before = Camera(position=rng.uniform(-100, 100, 3), yaw=float(rng.uniform(-3, 3)), pitch=float(rng.uniform(-0.5, 0.5)))
    after = Camera(position=before.position + rng.uniform(-4, 4, 3), yaw=before.yaw + float(rng.uniform(-0.08, 0.08)),
                   pitch=before.pitch + float(rng.uniform(-0.05, 0.05)))
    history = FroxelHistory(gpu)
    first_tex, first = volume_texture(gpu.ctx, smooth_volume(rng, (*shape[:2], shape[2] + 1)))
    second_tex, second = volume_texture(gpu.ctx, smooth_volume(rng, (*shape[:2], shape[2] + 1)))
    try:
        history.resolve(HistoryFrame(gpu, before, shape[:2], 7), first_tex, range_, knee, 0.25)
        assert np.array_equal(history.read(), first) and history.frames == 1
        history.resolve(HistoryFrame(gpu, after, shape[:2], 8), second_tex, range_, knee, 0.25)
        got = history.read()
        basis_before, basis_after = view_basis(before, aspect), view_basis(after, aspect)
        want = history_reference(second, first, basis_after, after.position, basis_before, before.position, range_,
                                 knee, 0.5)             # the running mean's 1 / (n + 1) = 1/2 > 0.25 at n = 1
        assert history.frames == 2 and np.isfinite(got).all()
        # the previous view's uv of each froxel's point, to leave out those on its edge
        from atmos.froxels import column_rays, froxel_distance
        _, dirs = column_rays(basis_after, shape[0], shape[1])
        bounds = froxel_distance(np.arange(shape[2] + 1) / shape[2], range_, knee)
        p = after.position + dirs[:, None, :] * bounds[None, :, None] - before.position
        q = p @ np.linalg.inv(basis_before).T
        uv = (q[..., :2] / q[..., 2:] + 1.0) * 0.5
        edge = (np.abs(uv) < 1e-4) | (np.abs(uv - 1.0) < 1e-4)
        keep = ~edge.any(-1).reshape(shape[0], shape[1], shape[2] + 1)
        steps = max(np.abs(np.diff(first, axis=a)).max() for a in range(3))
        weight_error = 0.0 if filter_bits is None else 3.0 * steps / 2.0 ** (filter_bits + 1)
        bound = 2.0 * F16 * np.abs(want).max() + weight_error + 1e-3 * steps     # 1e-3: float32 positions
        error = np.abs(got - want)[keep]
        assert error.max() <= bound, (error.max(), bound)
        assert keep.mean() > 0.9
        assert not np.allclose(got, second, atol=1e-2), "the history must weigh in"
    finally:
        history.release()
        for tex in (first_tex, second_tex):
            tex.release()
    assert gpu.ctx.error == "GL_NO_ERROR"


def test_the_jitter_runs_through_each_slice_and_stops_without_history(gpu, rng):
    """froxel_jitter: the middle in frame 0 and where not jittered; otherwise a sequence that fills [0, 1)
    evenly (every sixteenth of it visited in the first 32 frames); the GLSL function is the same number at
    any frame index (32-bit fixed point: exact in float32), up to 2^32 - 1."""
    from atmos.gpu.uniforms import bind_buffers, write_uniforms
    assert froxel_jitter(0) == 0.5 and all(froxel_jitter(n, False) == 0.5 for n in range(10))
    seq = np.array([froxel_jitter(n) for n in range(32)])
    assert ((seq >= 0.0) & (seq < 1.0)).all()
    assert len(set(np.floor(seq * 16).astype(int))) == 16
    frames = np.r_[np.arange(40), rng.integers(0, 2**32, 88, dtype=np.uint64), 2**32 - 1].astype(np.uint32)
    program = gpu.program(compute_shader="test/froxel_jitter.comp")
    given, out = gpu.ctx.buffer(frames.tobytes()), gpu.ctx.buffer(reserve=4 * len(frames))
    try:
        for jittered in (True, False):
            write_uniforms(program, count=len(frames), jittered=int(jittered))
            bind_buffers(program, Frames=given, Jitters=out)
            dispatch(program, -(-len(frames) // 64))
            got = np.frombuffer(out.read(), np.float32)
            np.testing.assert_array_equal(got, [froxel_jitter(int(n), jittered) for n in frames])
    finally:
        given.release()
        out.release()
