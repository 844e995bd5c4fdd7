import numpy as np
import pytest

from atmos.gpu import ShaderError
from atmos.gpu.context import GpuError, _check_version
from atmos.gpu.shaders import load_source
from conftest import TEST_SHADERS


def test_headless_context_is_gl43(gpu, ctx):
    assert ctx.version_code >= 430
    info = gpu.info()
    assert "GL_RENDERER" in info and "GL_VERSION" in info


def test_old_gl_is_a_clear_error():
    class Old:
        version_code = 330
        info = {"GL_VERSION": "3.3 Mesa", "GL_RENDERER": "toy"}
    with pytest.raises(GpuError, match=r"needs OpenGL 4.3.*3.3 Mesa.*toy"):
        _check_version(Old())


def test_unusable_backend_is_a_clear_error():
    from atmos.gpu import create_headless
    with pytest.raises(GpuError, match="no usable OpenGL"):
        create_headless(backend="no-such-backend")


def test_compile_error_names_file_and_line(gpu, ctx):
    with pytest.raises(ShaderError) as info:
        gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/broken.frag")
    assert f"{TEST_SHADERS}/broken.frag:7" in str(info.value)


def test_error_in_included_file_names_the_include(gpu, ctx):
    with pytest.raises(ShaderError) as info:
        gpu.program(compute_shader="test/broken_include.comp")
    assert f"{TEST_SHADERS}/broken_lib.glsl:4" in str(info.value)


def test_include_and_defines(ctx):
    source = load_source("test/broken_include.comp", {"ANSWER": 42})
    assert source.files == ["test/broken_include.comp", "test/broken_lib.glsl"]
    assert "#define ANSWER 42" in source.text


def test_missing_file_is_named():
    with pytest.raises(ShaderError, match="shaders/nope.frag"):
        load_source("nope.frag")


def test_programs_compile_once(gpu, ctx):
    a = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/solid.frag")
    b = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/solid.frag")
    assert a is b
    assert "test/solid.frag" in gpu.compiled_files


def test_offscreen_target_renders_and_reads_back(gpu, ctx):
    program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/solid.frag")
    program["color"].value = (1.0, 0.5, 0.0, 1.0)
    vao = ctx.vertex_array(program, [])
    gpu.target.use()
    vao.render(vertices=3)
    pixels = gpu.read_pixels()
    vao.release()
    assert pixels.shape == (gpu.size[1], gpu.size[0], 3)
    assert np.all(np.abs(pixels.astype(int) - [255, 128, 0]) <= 1)


def test_resize_to_zero_keeps_a_one_pixel_target(gpu, ctx):
    old = gpu.size
    gpu.resize((0, 0))
    assert gpu.size == (1, 1) and gpu.read_pixels().shape == (1, 1, 3)
    gpu.resize(old)


def test_a_frame_the_gpu_cannot_make_is_a_clear_error_and_the_old_frame_stays(monkeypatch):
    """Out of GPU memory at a huge size shows as an incomplete framebuffer: a GpuError naming the size
    (headless resize) or the pass, instead of moderngl's bare message; nothing is half-applied."""
    import moderngl
    from atmos.app import App
    from atmos.defaults import DefaultPlugins
    from atmos.gpu import create_headless
    gpu = create_headless((32, 24))
    try:
        def incomplete(self, *args, **kwargs):
            raise moderngl.Error("the framebuffer is not complete (INCOMPLETE_ATTACHMENT)")
        with monkeypatch.context() as m:
            m.setattr(moderngl.Context, "framebuffer", incomplete)
            with pytest.raises(GpuError, match=r"could not make a 64x48 frame .*INCOMPLETE_ATTACHMENT.*smaller size"):
                gpu.resize((64, 48))
        assert gpu.size == (32, 24) and gpu.read_pixels().shape == (24, 32, 3)
        app = App(gpu).add_plugins(DefaultPlugins())
        with monkeypatch.context() as m:
            m.setattr(moderngl.Context, "framebuffer", incomplete)
            with pytest.raises(GpuError, match=r"pass '\w+': the GPU could not make a 32x24 framebuffer"):
                app.run_frames(1)
        app.close()
    finally:
        gpu.release()
