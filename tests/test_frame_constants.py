"""The frame block (shaders/lib/frame.glsl, atmos.frame_constants): the std140 bytes Python packs read
back member by member in a compute shader as the driver lays them out; the graph writes it once per
frame; the compiler check keeps its binding to it."""
import math

import numpy as np
import pytest

from atmos import Camera, Sun
from atmos.camera import camera_matrices
from atmos.frame_constants import FRAME_BINDING, FRAME_SIZE, LAYOUT, bind_frame, frame_constants, pack_frame
from atmos.gpu.shaders import ShaderError, compile_program, load_source

COPY = """#version 430
#include "lib/frame.glsl"
layout(local_size_x = 1) in;
layout(std430, binding = 1) buffer Out { float o[]; };
void main() {
    int k = 0;
    for (int c = 0; c < 4; c++) for (int r = 0; r < 4; r++) o[k++] = view_proj[c][r];
    for (int c = 0; c < 4; c++) for (int r = 0; r < 4; r++) o[k++] = inv_view_proj[c][r];
    for (int c = 0; c < 3; c++) for (int r = 0; r < 3; r++) o[k++] = view_basis[c][r];
    for (int i = 0; i < 3; i++) o[k++] = camera_pos[i];
    o[k++] = near;
    for (int i = 0; i < 3; i++) o[k++] = sun_dir[i];
    o[k++] = far;
    for (int i = 0; i < 3; i++) o[k++] = sun_color[i];
    o[k++] = time;
    for (int i = 0; i < 3; i++) o[k++] = sky_ambient[i];
    o[k++] = uintBitsToFloat(frame_index);
    o[k++] = jitter.x; o[k++] = jitter.y;
    o[k++] = resolution.x; o[k++] = resolution.y;
}
"""
ORDER = ("view_proj", "inv_view_proj", "view_basis", "camera_pos", "near", "sun_dir", "far", "sun_color", "time",
         "sky_ambient", "frame_index", "jitter", "resolution")


def random_scene(rng):
    camera = Camera(position=rng.uniform(-5e3, 5e3, 3), yaw=rng.uniform(-math.pi, math.pi),
                    pitch=rng.uniform(-1.4, 1.4), roll=rng.uniform(-1, 1), fov_y=rng.uniform(0.3, 2.0),
                    near=float(rng.uniform(0.05, 2.0)), far=float(rng.uniform(1e3, 1e6)))
    sun = Sun(direction=rng.normal(size=3), color=rng.uniform(0, 20, 3), ambient=rng.uniform(0, 2, 3))
    size = (int(rng.integers(1, 4096)), int(rng.integers(1, 4096)))
    return camera, sun, size


def expected(camera, sun, size, time, frame_index, jitter) -> np.ndarray:
    """The members' float32 values in ORDER, each matrix column by column (the frame_index's bits)."""
    m = camera_matrices(camera, size[0] / size[1])
    parts = [np.asarray(m.view_proj, np.float32).T.ravel(), np.asarray(np.linalg.inv(m.view_proj), np.float32).T.ravel(),
             np.asarray(m.view_basis, np.float32).T.ravel(), camera.position, [camera.near], sun.direction, [camera.far],
             sun.color, [time], sun.ambient, np.array([frame_index], np.uint32).view(np.float32), jitter, size]
    return np.concatenate([np.asarray(p, np.float32).ravel() for p in parts])


def read_members(gpu, data: bytes) -> np.ndarray:
    program = compile_program(gpu.ctx, {"compute_shader": load_source_text(COPY)})
    block = gpu.ctx.buffer(data)
    out = gpu.ctx.buffer(reserve=4 * 64)
    try:
        assert program["Frame"].size == FRAME_SIZE        # the driver's block size is what Python packs
        block.bind_to_uniform_block(FRAME_BINDING)
        out.bind_to_storage_buffer(1)
        program.run(1)
        return np.frombuffer(out.read(), np.float32)
    finally:
        for obj in (program, block, out):
            obj.release()


def load_source_text(text):
    """A GlslSource of ``text`` with its includes expanded (through a one-off shader file)."""
    import tempfile
    from pathlib import Path

    from atmos.gpu.shaders import add_shader_path, remove_shader_path
    with tempfile.TemporaryDirectory() as d:
        Path(d, "copy.comp").write_text(text)
        add_shader_path(d, prefix="frame_test")
        try:
            return load_source("frame_test/copy.comp")
        finally:
            remove_shader_path(d, prefix="frame_test")


def test_layout_offsets_are_std140():
    offset = 0
    for name in ORDER:
        start, count = LAYOUT[name]
        if name.endswith("view_proj"):
            align, length = 16, 64
        elif name == "view_basis":
            align, length = 16, 48
        elif count == 3:
            align, length = 16, 12
        elif count == 2:
            align, length = 8, 8
        else:
            align, length = 4, 4
        offset = -(-offset // align) * align
        assert start == offset, name
        offset += length
    assert -(-offset // 16) * 16 == FRAME_SIZE


@pytest.mark.parametrize("draw", range(4))
def test_packing_reads_back_member_by_member(ctx, gpu, rng, draw):
    camera, sun, size = random_scene(rng)
    time, frame_index = float(rng.uniform(0, 1e5)), int(rng.integers(0, 2**32))
    jitter = tuple(rng.uniform(-0.5, 0.5, 2))
    data = pack_frame(camera, sun, size, time, frame_index, jitter)
    assert len(data) == FRAME_SIZE
    got, want = read_members(gpu, data), expected(camera, sun, size, time, frame_index, jitter)
    assert np.array_equal(got[:len(want)].view(np.uint32), want.view(np.uint32))


def test_bind_frame_outside_a_graph(ctx, gpu):
    camera, sun = Camera(position=(1.0, 2.0, 3.0), near=0.5, far=900.0), Sun(direction=(0.0, 1.0, 0.0))
    bind_frame(gpu, camera, sun, (320, 200), time=2.5, frame_index=7)
    assert frame_constants(gpu).data == pack_frame(camera, sun, (320, 200), 2.5, 7)
    program = compile_program(gpu.ctx, {"compute_shader": load_source_text(COPY)})
    out = gpu.ctx.buffer(reserve=4 * 64)
    try:
        out.bind_to_storage_buffer(1)
        program.run(1)              # the block bound by bind_frame
        got = np.frombuffer(out.read(), np.float32)
    finally:
        program.release()
        out.release()
    want = expected(camera, sun, (320, 200), 2.5, 7, (0.0, 0.0))
    assert np.array_equal(got[:len(want)].view(np.uint32), want.view(np.uint32))


def test_the_graph_writes_the_block_once_per_frame(ctx, gpu):
    from atmos import App, DefaultPlugins, GroundPlugin, SkyGradientPlugin
    app = App(gpu).add_plugins(DefaultPlugins(fly_camera=False), SkyGradientPlugin(), GroundPlugin())
    app.insert_resource(Camera(position=(0.0, 3.0, 9.0), pitch=-0.2))
    block = frame_constants(gpu)
    writes = []
    block.write = lambda data, write=block.write: (writes.append(data), write(data))[1]
    try:
        app.run_frames(3, 1 / 30)
        assert len(writes) == 3                      # one write per frame, whatever the passes
        data = np.frombuffer(block.data, np.float32)
        assert data.view(np.uint32)[59] == app.clock.frame == 3
        assert np.array_equal(data[44:47], np.float32([0.0, 3.0, 9.0]))
        assert np.array_equal(data[62:64], np.float32(gpu.size))
        assert data[55] == np.float32(app.clock.frame_time)
    finally:
        del block.write
        app.close()


def test_a_second_block_at_the_frame_binding_is_refused(ctx, gpu):
    text = """#version 430
#include "lib/frame.glsl"
layout(std140, binding = 0) uniform Other { vec4 x; };
layout(local_size_x = 1) in;
layout(std430, binding = 1) buffer Out { vec4 o[]; };
void main() { o[0] = x + vec4(near); }
"""
    with pytest.raises(ShaderError, match="binding|share"):
        compile_program(gpu.ctx, {"compute_shader": load_source_text(text)})


def test_two_blocks_sharing_a_binding_are_refused(ctx, gpu):
    text = """#version 430
layout(std140, binding = 3) uniform A { vec4 a; };
layout(std140, binding = 3) uniform B { vec4 b; };
layout(local_size_x = 1) in;
layout(std430, binding = 1) buffer Out { vec4 o[]; };
void main() { o[0] = a + b; }
"""
    with pytest.raises(ShaderError, match="share uniform buffer binding 3"):
        compile_program(gpu.ctx, {"compute_shader": load_source_text(text)})


def test_a_block_without_a_binding_is_refused(ctx, gpu):
    text = """#version 430
layout(std140) uniform A { vec4 a; };
layout(local_size_x = 1) in;
layout(std430, binding = 1) buffer Out { vec4 o[]; };
void main() { o[0] = a; }
"""
    with pytest.raises(ShaderError, match="uniform block A needs layout"):
        compile_program(gpu.ctx, {"compute_shader": load_source_text(text)})
