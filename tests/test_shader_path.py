"""The shader search path: a third-party plugin ships its own GLSL (tests/data/mypkg/shaders/),
includes atmos's lib/, draws through an App; its errors name its real files and lines."""
from pathlib import Path

import numpy as np
import pytest

from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.gpu import ShaderError, add_shader_path, load_source, remove_shader_path, shader_paths
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures
from atmos.graph import FullscreenPass, PassContext
from atmos.scene_uniforms import set_scene_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR

SHADERS = Path(__file__).parent / "data" / "mypkg" / "shaders"


# -- a third-party plugin, as a package outside atmos would write it ----------------------------------
class GlowPass(FullscreenPass):
    """Paints what is above the horizon red and what is below it blue (``mypkg/glow.frag``)."""
    name = "glow"
    phase = "opaque"
    fragment = "mypkg/glow.frag"

    def execute(self, frame: PassContext) -> None:
        frame.framebuffer(color=[COLOR]).use()
        set_scene_uniforms(self.program, frame.view)
        frame.fullscreen(self.program)


class GlowPlugin(Plugin):
    """Registers its shader directory under the prefix ``mypkg`` and adds :class:`GlowPass`."""

    def build(self, app) -> None:
        add_shader_path(SHADERS, prefix="mypkg")
        app.graph.add_pass(GlowPass(self))


@pytest.fixture
def mypkg():
    """The plugin's directory on the search path for one test (the path is process-wide)."""
    add_shader_path(SHADERS, prefix="mypkg")
    yield SHADERS
    remove_shader_path(SHADERS, prefix="mypkg")


def test_third_party_plugin_draws_with_its_own_shader_through_an_app(fresh_gpu):
    app = App(fresh_gpu).add_plugins(DefaultPlugins(overlay=False), GlowPlugin())
    try:
        app.run_frames(2)
        pixels = fresh_gpu.read_pixels().astype(int)       # first row at the top
    finally:
        app.close()
        remove_shader_path(SHADERS, prefix="mypkg")
    h = pixels.shape[0]
    top, bottom = pixels[: h // 3], pixels[-(h // 3):]      # the default camera looks at the horizon
    assert (top[..., 0] > 200).all() and (top[..., 2] < 30).all(), "sky half is not the plugin's red"
    assert (bottom[..., 2] > 200).all() and (bottom[..., 0] < 30).all(), "ground half is not the plugin's blue"
    assert "mypkg/glow.frag" in fresh_gpu.compiled_files


def test_plugin_file_includes_atmos_lib_and_its_own_pieces(mypkg):
    source = load_source("mypkg/glow.frag")
    assert source.files == ["mypkg/glow.frag", "lib/view_ray.glsl", "mypkg/palette.glsl"]
    assert "vec3 view_ray_dir(vec2 uv, mat3 view_basis)" in source.text     # atmos's shaders/lib/
    assert "const vec3 GLOW_UP" in source.text


def test_compile_error_names_the_plugin_file_and_line(gpu, ctx, mypkg):
    with pytest.raises(ShaderError) as info:
        gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/broken.frag")
    assert f"{SHADERS}/broken.frag:7:" in str(info.value)
    with pytest.raises(ShaderError) as info:
        gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/broken_include.frag")
    assert f"{SHADERS}/broken_piece.glsl:3:" in str(info.value)


def test_samplers_declare_their_units_once_and_textures_are_bound_by_name(gpu, ctx, mypkg):
    program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/two_textures.frag")
    textures = {name: ctx.texture((1, 1), 1, np.array([value], "f4").tobytes(), dtype="f4")
                for name, value in (("first", 0.25), ("second", 0.75), ("unused", 0.5), ("stray", 9.0))}
    target = ctx.texture((1, 1), 4, dtype="f4")
    fbo, vao = ctx.framebuffer([target]), ctx.vertex_array(program, [])
    try:
        textures["stray"].use(0)                                            # what unit 0 held before
        assert sorted(bind_textures(program, textures)) == [4, 9]           # the GLSL's units; "unused" skipped
        fbo.use()
        vao.render(vertices=3)
        assert np.frombuffer(target.read(), "f4")[:2].tolist() == [0.25, 0.75]
    finally:
        gpu.target.use()
        for obj in (vao, fbo, target, *textures.values()):
            obj.release()
    with pytest.raises(ShaderError) as info:
        gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/shared_unit.frag")
    message = str(info.value)
    assert "second and first" in message and "share texture unit 4" in message
    assert f"{SHADERS}/shared_unit.frag:4" in message and f"{SHADERS}/unit_piece.glsl:2" in message
    with pytest.raises(ShaderError) as info:
        gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/unbound_sampler.frag")
    assert f"{SHADERS}/unbound_sampler.frag:3: sampler nowhere needs layout(binding = N)" in str(info.value)


def test_images_and_storage_blocks_are_bound_by_name_with_their_declared_access(gpu, ctx, mypkg):
    program = gpu.program(compute_shader="mypkg/images.comp")
    assert program.extra["images"] == {"src": (2, True, False), "dst": (5, False, True)}
    src = ctx.texture((1, 1), 1, np.array([0.25], "f4").tobytes(), dtype="f4")
    dst = ctx.texture((1, 1), 1, dtype="f4")
    out = ctx.buffer(reserve=4)
    try:
        bind_images(program, src=src, dst=dst, missing=src)                 # "missing": not in the program
        bind_buffers(program, Out=out)
        program.run(1)
        ctx.memory_barrier()
        assert np.frombuffer(dst.read(), "f4")[0] == 0.5 and np.frombuffer(out.read(), "f4")[0] == 1.25
    finally:
        for obj in (src, dst, out):
            obj.release()
    with pytest.raises(ShaderError) as info:
        gpu.program(compute_shader="mypkg/shared_buffer.comp")
    assert "buffer Out and In" in str(info.value) and "share storage buffer binding 1" in str(info.value)


def test_unknown_file_names_the_search_path(mypkg):
    with pytest.raises(ShaderError) as info:
        load_source("mypkg/nope.frag")
    message = str(info.value)
    assert "shader file not found: mypkg/nope.frag" in message
    assert "shaders/mypkg/nope.frag" in message and f"{SHADERS}/nope.frag" in message   # every place tried
    assert "shaders/ (atmos.shaders)" in message and f"{SHADERS}/ (prefix mypkg/)" in message
    with pytest.raises(ShaderError) as info:                  # a missing include names who included it
        load_source("mypkg/missing_include.frag")
    assert "mypkg/not_shipped.glsl" in str(info.value)
    assert f"included from {SHADERS}/missing_include.frag:3" in str(info.value)
    with pytest.raises(ShaderError, match="relative"):
        load_source("../secrets.frag")


def test_first_match_wins_and_a_prefix_scopes_a_directory(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    for d, word in ((one, "ONE"), (two, "TWO")):
        (d / "fx").mkdir(parents=True)
        (d / "fx" / "pick.glsl").write_text(f"// {word}\n")
        (d / "lib").mkdir()
        (d / "lib" / "view_ray.glsl").write_text("// not atmos's\n")
    before = shader_paths()                                  # other tests' plugins may have added some
    assert before[0] == "shaders/ (atmos.shaders)"
    add_shader_path(one)
    add_shader_path(two)
    add_shader_path(one)                                     # twice: no second entry
    try:
        assert shader_paths() == before + [f"{one}/", f"{two}/"]
        assert _text("fx/pick.glsl") == "// ONE"             # registration order
        assert "view_ray_dir" in _text("lib/view_ray.glsl")  # atmos's own files come first
        remove_shader_path(one)
        assert _text("fx/pick.glsl") == "// TWO"
        add_shader_path(two / "fx", prefix="theirs/fx")
        assert _text("theirs/fx/pick.glsl") == "// TWO"      # the prefix maps onto the directory
        with pytest.raises(ShaderError, match="not found"):
            load_source("pick.glsl")                         # a prefixed directory serves its names only
    finally:
        for d, prefix in ((one, None), (two, None), (two / "fx", "theirs/fx")):
            remove_shader_path(d, prefix)
    assert shader_paths() == before
    with pytest.raises(ValueError, match="not found"):
        add_shader_path(tmp_path / "missing")
    for bad in ("", "/mypkg", "mypkg/", "a/../b", 3):
        with pytest.raises(ValueError, match="prefix"):
            add_shader_path(tmp_path, prefix=bad)


def _text(name: str) -> str:
    """The text of an include-only file (no #version): read through the search path."""
    from atmos.gpu.shaders import _locate
    return _locate(name)[1].strip()


def test_an_include_line_may_end_in_a_comment(tmp_path):
    (tmp_path / "main.comp").write_text('#version 430\n#include "lib/hdr_max.glsl"   // HDR_MAX\nvoid main() {}\n')
    add_shader_path(tmp_path, prefix="commented")
    try:
        source = load_source("commented/main.comp")
    finally:
        remove_shader_path(tmp_path, prefix="commented")
    assert source.files == ["commented/main.comp", "lib/hdr_max.glsl"] and "#include" not in source.text
