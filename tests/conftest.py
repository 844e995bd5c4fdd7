"""Shared fixtures: one headless EGL context for the whole session; every GL test ends on GL_NO_ERROR.
Where the reference GLSL compiler is installed, every program the tests build is also checked by it
(atmos.gpu.portability; tests/test_glsl_portability.py says when it is missing)."""
import os
import shutil

import pytest

from atmos.gpu import add_shader_path, create_headless
from atmos.gpu.portability import COMPILER, ENV
from atmos.gpu.uniforms import bind_buffers, bind_textures

os.environ.setdefault("ATMOS_HEADLESS", "1")
if shutil.which(COMPILER):
    os.environ.setdefault(ENV, "1")
TEST_SHADERS = os.path.join(os.path.dirname(__file__), "data", "shaders")
add_shader_path(TEST_SHADERS, prefix="test")          # the tests' own GLSL: "test/solid.frag", ...


@pytest.fixture(scope="session")
def gpu():
    """The session's headless GpuContext (Mesa llvmpipe here, the NVIDIA driver on a GPU machine)."""
    context = create_headless((256, 144))
    yield context
    context.release()


@pytest.fixture
def ctx(gpu):
    """The session's moderngl.Context (made current: tests that make contexts of their own switch
    away from it); the test fails if it leaves an OpenGL error behind."""
    gpu.make_current()
    gpu.ctx.error  # clear errors left by earlier tests' teardown
    yield gpu.ctx
    assert gpu.ctx.error == "GL_NO_ERROR"


@pytest.fixture(scope="session")
def filter_bits(gpu):
    """The context's texture filter's sub-texel weight precision, measured: None where it filters in
    float (Mesa's llvmpipe), else its bits (8 on NVIDIA: a sample is up to 1/512 of the two texels'
    difference off). Tests of passes that sample through the filter give it to their references."""
    import numpy as np
    import moderngl
    ctx = gpu.ctx
    gpu.make_current()
    n = 4097
    texture = ctx.texture((2, 1), 1, np.array([0.0, 1.0], "f4").tobytes(), dtype="f4")
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    out = ctx.buffer(reserve=4 * n)
    program = gpu.program(compute_shader="test/filter_probe.comp")
    try:
        bind_textures(program, s=texture)
        bind_buffers(program, Out=out)
        program.run(n)
        ctx.memory_barrier()
        got = np.frombuffer(out.read(), "f4").astype(np.float64)
    finally:
        for obj in (out, texture):
            obj.release()
    error = np.abs(got - np.arange(n) / 4096.0).max()    # u from texel centre 0.25 to 0.75: weight k / 4096
    return None if error < 1e-6 else int(np.floor(-np.log2(2.0 * error)))


@pytest.fixture
def rng(request):
    """A fresh random generator per test; the seed is printed so a failure can be replayed
    (``ATMOS_TEST_SEED=<seed> pytest <the test>``)."""
    import numpy as np
    seed = int(os.environ.get("ATMOS_TEST_SEED") or int.from_bytes(os.urandom(4), "little"))
    print(f"rng seed {seed}")
    return np.random.default_rng(seed)


@pytest.fixture
def fresh_gpu():
    """A GpuContext of its own (64×40) for tests that count compiled shaders or allocations."""
    context = create_headless((64, 40))
    yield context
    assert context.ctx.error == "GL_NO_ERROR"
    context.release()


@pytest.fixture(scope="session", autouse=True)
def out_folder():
    """The repository's out/ folder, where tests save the pictures they render to be looked at
    (a fresh clone has none)."""
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "out"
    path.mkdir(exist_ok=True)
    return path


@pytest.fixture(scope="session")
def display():
    """A virtual X server (Xvfb) for the window tests, one per test session; its DISPLAY name."""
    import subprocess
    import time
    number = 90 + os.getpid() % 800
    server = subprocess.Popen(["Xvfb", f":{number}", "-screen", "0", "800x600x24"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)
    yield f":{number}"
    server.terminate()
    server.wait()
