"""No stalls: what a running scene reads back from the GPU, counted per frame with GLMeter.

The thesis design brings only the tiny max maps back, once per simulation step; atmos copies them
into a pixel buffer when the step computes them and reads that buffer when the set is first drawn.
The far field's cover measure (which sizes its tile) comes back the same way: copied on the GPU when
a step's sets are first drawn, read when the next step's are.
The render graph's timer queries (only while timings are on) are read once their results are in,
never waiting. Nothing else (textures, framebuffers, glFinish) may wait for the GPU in a frame.
"""
import moderngl
import numpy as np

from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.gpu.gl_meter import GLMeter
from atmos.plugins.clouds import CloudSimulation, DensityMaps, reference
from atmos.runner import build_app

MAPS, FAR = ("Buffer.read", "plugins/clouds/simulation/density_maps.py"), ("Buffer.read", "plugins/clouds/far_field/layer.py")
ALLOWED = {MAPS, FAR}


def test_a_running_sunset_reads_back_only_the_max_maps_once_per_step_even_with_timings_on():
    gpu = create_headless((48, 27))
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True), gpu)
    try:
        app.graph.timings_enabled = True
        app.run_frames(4, 1 / 30)
        sim = app.resource(CloudSimulation)
        steps, frames = sim.job.step, 45
        dropped = app.graph._timers.dropped
        with GLMeter() as meter:
            app.run_frames(frames, 1 / 30)
        steps = sim.job.step - steps
        kept = len(app.graph.compile().kept)
        counts = meter.readback_counts()
        where = {(call, place.rsplit(":", 1)[0]) for call, place in counts}
        assert where <= ALLOWED, f"readbacks beyond the max maps: {sorted(where - ALLOWED)}"
        by_place = {key: sum(n for (c, place), n in counts.items() if (c, place.rsplit(":", 1)[0]) == key)
                    for key in ALLOWED}
        timers = app.graph._timers
        assert meter.calls["TimerQuery.begin"] == kept * frames - (timers.dropped - dropped), "one timer query per kept pass"
        assert meter.calls["TimerQuery.poll"] >= meter.calls["TimerQuery.begin"] - 4 * kept, \
            "polled until the result is in"
        assert meter.calls["TimerQuery.result"] == meter.calls["Query.elapsed"] == 0
        assert set(app.graph.timings) == set(app.graph.compile().kept)
        assert steps >= 2, "the window must span simulation steps"
        assert abs(by_place[MAPS] - steps) <= 1, "the max maps come back once per step"
        assert abs(by_place[FAR] - steps) <= 1, "the far field's measure comes back once per step"
        assert meter.calls["Texture3D.read"] == meter.calls["TextureArray.read"] == 0
        assert meter.calls["Context.finish"] == 0
    finally:
        app.close()
        gpu.release()


def test_max_maps_through_the_pixel_buffer_equal_a_direct_read(ctx, gpu, rng):
    shape = (40, 12, 36)
    density = (rng.random(shape) < 0.05) * rng.random(shape)
    density[20:] = 0.0                                   # empty segments too
    texture = ctx.texture3d(shape, 1, np.ascontiguousarray(density.transpose(2, 1, 0), np.float32).tobytes(),
                            dtype="f4")
    maps = DensityMaps(gpu, shape, band_height=4, group_size=(16, 8))
    try:
        maps.run(texture)
        with GLMeter() as meter:
            maps.request_max_maps()
        assert meter.readbacks == [] and meter.calls["TextureArray.read_into"] == 1, "the copy waits for nothing"
        assert maps.requested
        copied = maps.collect_max_maps()
        assert not maps.requested
        np.testing.assert_array_equal(copied, maps.read_max_maps())
        np.testing.assert_allclose(copied, reference.density_maps(density, 4, (16, 8))[1], rtol=1e-5, atol=1e-6)
        assert (copied[0] > 0).any() and (copied[0] == 0).any()
    finally:
        maps.release()
        texture.release()


def test_the_meter_restores_moderngl_and_names_the_caller(ctx):
    render = moderngl.VertexArray.render
    buffer = ctx.buffer(reserve=16)
    with GLMeter() as meter:
        buffer.write(bytes(16))
        buffer.read()
        ctx.finish()
    assert moderngl.VertexArray.render is render and "wrapped" not in repr(moderngl.Buffer.read)
    assert [r.call for r in meter.readbacks] == ["Buffer.read", "Context.finish"]
    assert all(r.where.startswith("tests/test_readbacks.py:") for r in meter.readbacks)
    assert meter.calls["Buffer.write"] == 1 and meter.work_s >= 0.0
    buffer.release()
