"""The reference compiler's check (atmos.gpu.portability): on in the suite, refusing what the
specification does not allow with the file and line, remembering what it accepted."""
import shutil

import pytest

from atmos.gpu import ShaderError, add_shader_path, load_source, remove_shader_path
from atmos.gpu import portability
from atmos.gpu.portability import COMPILER, ENV

needs_compiler = pytest.mark.skipif(shutil.which(COMPILER) is None, reason=f"{COMPILER} is not installed")


def test_the_suite_checks_every_program_where_it_must(gpu):
    """CI runs without a GPU, on a software rasterizer: there the check must be on. On a GPU machine
    the driver itself compiles every shader, and the check is optional."""
    if shutil.which(COMPILER) is None:
        if gpu.software:
            pytest.fail(f"{COMPILER} is not installed: install Debian's glslang-tools (setup.sh does) so that "
                        "every shader the tests compile is also checked by the reference compiler")
        pytest.skip(f"{COMPILER} is not installed; {gpu.info()['GL_RENDERER']} compiles every shader itself")
    assert portability.check_enabled(), f"{ENV} is not 1 although {COMPILER} is installed (tests/conftest.py sets it)"


@pytest.fixture
def shaders(tmp_path):
    add_shader_path(tmp_path, prefix="portable")
    yield tmp_path
    remove_shader_path(tmp_path, prefix="portable")


@needs_compiler
def test_a_vendor_extension_the_driver_accepts_is_refused_by_file_and_line(fresh_gpu, shaders, monkeypatch):
    monkeypatch.setenv(ENV, "1")
    (shaders / "vendor.comp").write_text("#version 430\n#extension GL_MESA_shader_integer_functions : enable\n"
                                         "layout(local_size_x = 1) in;\nvoid main() {}\n")
    with pytest.raises(ShaderError, match=rf"{shaders}/vendor.comp:2: warning: .*#extension.*GL_MESA"):
        fresh_gpu.program(compute_shader="portable/vendor.comp", defines={"N": 3})
    assert not fresh_gpu._programs, "a refused program is not kept"


@needs_compiler
def test_errors_name_each_stage_file_and_line(shaders):
    (shaders / "a.vert").write_text("#version 430\nout vec2 uv;\n\nvoid main() { uv = vec2(0.0); "
                                    "gl_Position = vec4(saturate(1.0)); }\n")
    (shaders / "a.frag").write_text("#version 430\nin vec2 uv;\nout vec4 color;\nvoid main() {\n"
                                    "    color = lerp(vec4(0.0), vec4(1.0), 0.5);\n}\n")
    sources = {"vertex_shader": load_source("portable/a.vert", {"K": 1}),
               "fragment_shader": load_source("portable/a.frag")}
    with pytest.raises(ShaderError) as error:
        portability.check_program(sources)
    text = str(error.value)
    assert f"{shaders}/a.vert:4: error: 'saturate'" in text and f"{shaders}/a.frag:5: error: 'lerp'" in text, text


@needs_compiler
def test_accepted_programs_are_checked_once(shaders, monkeypatch):
    (shaders / "ok.comp").write_text("#version 430\nlayout(local_size_x = 8) in;\nvoid main() {}\n")
    source = {"compute_shader": load_source("portable/ok.comp", {"SEED": 17})}
    portability.check_program(source)
    monkeypatch.setattr(portability.subprocess, "run", lambda *a, **k: pytest.fail("checked twice"))
    portability.check_program(source)


def test_a_missing_compiler_is_a_clear_error(shaders, monkeypatch):
    (shaders / "ok.comp").write_text("#version 430\nlayout(local_size_x = 4) in;\nvoid main() {}\n")
    monkeypatch.setattr(portability.shutil, "which", lambda name: None)
    with pytest.raises(ShaderError, match=rf"{ENV}=1 but {COMPILER} is not installed .*glslang-tools"):
        portability.check_program({"compute_shader": load_source("portable/ok.comp", {"SEED": 18})})
