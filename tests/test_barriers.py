"""Memory barriers come from declared uses (atmos.gpu.hazards): the binds, the graph's declarations,
transfers and draws; exactly the bits each producer -> consumer pair needs, once; nobody calls
glMemoryBarrier by hand; compute passes in the graph (ComputePass, frame.dispatch, frame.image)."""
from __future__ import annotations

import re
from pathlib import Path

import moderngl
import numpy as np
import pytest

import atmos
from atmos.gpu.hazards import Hazards, barrier_bit, bit_names, dispatch, dispatch_indirect, hazards_of
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures
from atmos.graph import (BufferDesc, ComputePass, GraphError, RenderGraph, RenderPass, TextureDesc,
                         work_groups)

ROOT = Path(__file__).resolve().parent.parent

FILL = """#version 430
layout(local_size_x = 4, local_size_y = 4) in;
layout(binding = 0, r32f) writeonly uniform image2D dst;
uniform float value;
void main() { imageStore(dst, ivec2(gl_GlobalInvocationID.xy), vec4(value + float(gl_GlobalInvocationID.x))); }
"""
COPY = """#version 430
layout(local_size_x = 4, local_size_y = 4) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, r32f) uniform image2D img;
layout(std430, binding = 0) buffer Out { float total; uint args[3]; };
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    imageStore(img, p, vec4(texelFetch(src, p, 0).r * 2.0));
    if (p == ivec2(0)) { total = texelFetch(src, p, 0).r; args[0] = 1u; args[1] = 1u; args[2] = 1u; }
}
"""
READ_ONLY = """#version 430
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer In { float values[]; };
layout(std430, binding = 1) writeonly buffer Res { float result; };
void main() { result = values[0] + 1.0; }
"""


@pytest.fixture
def recorded(gpu, monkeypatch):
    """The glMemoryBarrier calls made, as lists of bit names (Hazards.issue makes every one of them:
    test_no_code_issues_a_barrier_by_hand)."""
    calls = []
    original = Hazards.issue

    def record(self, bits):
        calls.append(bit_names(bits))
        return original(self, bits)
    monkeypatch.setattr(Hazards, "issue", record)
    hazards_of(gpu.ctx).settle()
    calls.clear()
    return calls


def _compile(gpu, source):
    """A compute program through the project's compiler (its binding checks and declared access)."""
    return gpu.program(compute_shader=_write(source))


_SOURCES: dict[str, str] = {}


def _write(source: str) -> str:
    """A shader file under a registered test folder, named by its content."""
    import hashlib
    import tempfile
    from atmos.gpu.shaders import add_shader_path
    folder = Path(tempfile.gettempdir()) / "atmos_barrier_shaders"
    folder.mkdir(exist_ok=True)
    name = hashlib.sha1(source.encode()).hexdigest()[:12] + ".comp"
    (folder / name).write_text(source)
    if "folder" not in _SOURCES:
        add_shader_path(folder, prefix="barrier_tests")
        _SOURCES["folder"] = str(folder)
    return f"barrier_tests/{name}"


def test_a_storage_write_then_reads_of_each_kind_get_exactly_their_bit_once(gpu, recorded):
    ctx = gpu.ctx
    tex = gpu.track(ctx.texture((8, 8), 1, dtype="f4"))
    out = gpu.track(ctx.texture((8, 8), 1, dtype="f4"))
    buf = gpu.track(ctx.buffer(reserve=16))
    fill, copy = _compile(gpu, FILL), _compile(gpu, COPY)
    bind_images(fill, dst=tex)
    fill["value"].value = 3.0
    dispatch(fill, 2, 2)
    assert recorded == []                                 # nothing was dirty before the first dispatch
    assert hazards_of(ctx).pending(tex)                   # the image store is not yet visible to anyone
    bind_textures(copy, src=tex)
    bind_images(copy, img=out)
    bind_buffers(copy, Out=buf)
    dispatch(copy, 2, 2)
    assert recorded == [["texture_fetch"]]                # sampled after an image store: that bit only
    bind_textures(copy, src=tex)
    bind_images(copy, img=out)                            # out: written by copy, now read-written again
    dispatch(copy, 2, 2)
    assert recorded[1:] == [["shader_image_access"]]     # tex is clean for fetches; out needs image access
    dispatch_indirect(fill, buf, 4)                       # args (after total) written by a storage block: a command
    assert recorded[2:] == [["command"]]
    values = np.frombuffer(out.read(), np.float32).reshape(8, 8)   # a readback: the texture-update bit
    assert recorded[3:] == [["texture_update"]]
    assert np.allclose(values[0], 2 * (3.0 + np.arange(8)))
    assert np.frombuffer(buf.read(4), np.float32)[0] == 3.0
    assert recorded[4:] == [["pixel_buffer", "buffer_update"]]
    assert not hazards_of(ctx).pending(buf) or "buffer_update" not in hazards_of(ctx).pending(buf)


def test_clean_objects_and_readonly_blocks_make_no_barrier(gpu, recorded):
    ctx = gpu.ctx
    values = gpu.track(ctx.buffer(np.array([5.0], np.float32).tobytes()))
    result = gpu.track(ctx.buffer(reserve=4))
    prog = _compile(gpu, READ_ONLY)
    for _ in range(3):
        bind_buffers(prog, In=values, Res=result)
        dispatch(prog, 1)
    # In is readonly (never dirty); Res is written each time: write after write orders the dispatches
    assert recorded == [["shader_storage"], ["shader_storage"]]
    assert hazards_of(ctx).pending(values) == []
    assert np.frombuffer(result.read(), np.float32)[0] == 6.0


def test_one_barrier_serves_every_bind_of_a_dispatch(gpu, recorded):
    ctx = gpu.ctx
    a, b = (gpu.track(ctx.texture((8, 8), 1, dtype="f4")) for _ in range(2))
    fill, copy = _compile(gpu, FILL), _compile(gpu, COPY)
    buf = gpu.track(ctx.buffer(reserve=16))
    for tex in (a, b):
        bind_images(fill, dst=tex)
        dispatch(fill, 2, 2)
    assert recorded == [] or recorded == [["shader_image_access"]]
    recorded.clear()
    bind_textures(copy, src=a)
    bind_images(copy, img=b)
    bind_buffers(copy, Out=buf)
    dispatch(copy, 2, 2)
    assert recorded == [["texture_fetch", "shader_image_access"]]   # one call, the bits of both uses


def test_a_dead_object_leaves_nothing_behind(gpu, recorded):
    ctx = gpu.ctx
    hazards = Hazards(ctx)
    tex = ctx.texture((4, 4), 1, dtype="f4")
    hazards.stage(tex)
    hazards.commit()
    assert hazards.pending(tex)
    tex.release()
    del tex
    assert hazards.settle() == 0 or recorded       # a released texture may still be referenced by moderngl
    assert hazards._dirty == {}


def test_barrier_bits_by_kind_and_access():
    assert barrier_bit("texture", "sampled") == moderngl.TEXTURE_FETCH_BARRIER_BIT
    assert barrier_bit("texture", "storage") == moderngl.SHADER_IMAGE_ACCESS_BARRIER_BIT
    assert barrier_bit("texture", "attachment") == moderngl.FRAMEBUFFER_BARRIER_BIT
    assert barrier_bit("buffer", "indirect") == moderngl.COMMAND_BARRIER_BIT
    assert barrier_bit("buffer", "uniform") == moderngl.UNIFORM_BARRIER_BIT
    assert barrier_bit("buffer", "attachment") == 0
    with pytest.raises(ValueError, match="'sample' is not one of: sampled, storage"):
        barrier_bit("texture", "sample")


def test_no_code_issues_a_barrier_by_hand():
    hits = []
    for folder in ("atmos", "plugins", "demos"):
        for path in (ROOT / folder).rglob("*.py"):
            if path.name == "hazards.py":
                continue
            for i, line in enumerate(path.read_text().splitlines(), 1):
                if re.search(r"memory_barrier\s*\(|\.run(_indirect)?\(\s*\*?\s*(self\.)?_?grid|glMemoryBarrier", line):
                    hits.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()}")
    assert hits == []


# -- the graph ------------------------------------------------------------------------------------
class Fill(ComputePass):
    name = "fill"
    phase = "clear"
    compute = ""
    local_size = (4, 4)

    def setup(self, builder):
        builder.create("field", TextureDesc((8, 8), components=1, dtype="f4", filter="nearest", storage=True),
                       access="storage")

    def execute(self, frame):
        self.program_["value"].value = 1.0
        frame.dispatch(self.program_, self.groups(frame.image("field").size), images={"dst": "field"})


class Show(RenderPass):
    name = "show"
    phase = "present"

    def setup(self, builder):
        builder.read("field")
        builder.write("screen")

    def execute(self, frame):
        self.seen = np.frombuffer(frame.resource("field").read(), np.float32).reshape(8, 8).copy()


def test_a_compute_pass_feeds_a_later_pass_through_the_graph_with_the_barrier_it_needs(gpu, recorded):
    graph = RenderGraph(gpu)
    fill, show = Fill(), Show()
    fill.program_ = _compile(gpu, FILL)
    graph.add_pass(fill)
    graph.add_pass(show)
    graph.import_resource("screen", gpu.target)
    graph.execute()
    # field: stored by 'fill'; 'show' declared a sampled read (the barrier before it), then reads it back
    assert recorded == [["texture_fetch"], ["texture_update"]]
    assert np.allclose(show.seen[0], 1.0 + np.arange(8))
    graph.execute()
    # the next frame's image store into the same pooled texture is ordered after the last one's
    assert recorded[2:] == [["shader_image_access"], ["texture_fetch"], ["texture_update"]]
    graph.release()


def test_storage_declarations_are_checked(gpu):
    with pytest.raises(ValueError, match="1, 2 or 4 components"):
        TextureDesc((4, 4), components=3, storage=True)
    with pytest.raises(ValueError, match="not be depth"):
        TextureDesc((4, 4), depth=True, storage=True)
    with pytest.raises(ValueError, match="BufferDesc.size must be a positive int"):
        BufferDesc(0)

    class Bad(RenderPass):
        name, phase = "bad", "clear"

        def setup(self, builder):
            builder.create("t", TextureDesc((4, 4)), access="storage")
            builder.side_effect()
    graph = RenderGraph(gpu)
    graph.add_pass(Bad())
    with pytest.raises(GraphError, match="has storage=False; give TextureDesc"):
        graph.compile()

    class Wrong(RenderPass):
        name, phase = "wrong", "clear"

        def setup(self, builder):
            builder.read("t", access="sampeld")
    graph = RenderGraph(gpu)
    graph.add_pass(Wrong())
    with pytest.raises(GraphError, match="access 'sampeld'; allowed: sampled, storage"):
        graph.compile()


def test_frame_image_needs_a_storage_declaration_and_buffers_are_pooled(gpu):
    seen = {}

    class Make(RenderPass):
        name, phase = "make", "clear"

        def setup(self, builder):
            builder.create("list", BufferDesc(64, clear=True))
            builder.create("img", TextureDesc((4, 4), components=1, dtype="f4"))
            builder.side_effect()

        def execute(self, frame):
            seen["buffer"] = frame.resource("list")
            seen["zeros"] = bytes(frame.resource("list").read())
            with pytest.raises(GraphError, match="as an image but declared it without access='storage'"):
                frame.image("img")
    graph = RenderGraph(gpu)
    graph.add_pass(Make())
    graph.execute()
    first = seen["buffer"]
    first.write(b"\x01" * 64)
    graph.execute()
    assert seen["buffer"] is first and seen["zeros"] == bytes(64)   # the same pooled buffer, cleared again
    assert "buffer 64 B cleared" in graph.dump()
    graph.release()


def test_work_groups_cover_the_size():
    assert work_groups((1920, 1080), (8, 8)) == (240, 135)
    assert work_groups((1, 1, 1), (4, 4, 4)) == (1, 1, 1)
    with pytest.raises(ValueError, match="differ in rank"):
        work_groups((4, 4), (8,))


def test_the_volumetric_fog_runs_as_one_compute_dispatch_per_frame(gpu):
    from atmos.gpu.gl_meter import GLMeter
    from atmos.plugins.volumetric_fog import VolumetricFogPlugin
    app = atmos.App(gpu).add_plugins(atmos.DefaultPlugins(overlay=False), VolumetricFogPlugin(steps=8))
    app.update(1 / 60)
    with GLMeter() as meter:
        app.update(1 / 60)
    assert meter.calls["ComputeShader.run"] == 2 and meter.calls["VertexArray.render"] == 0   # the fog, present
    assert "volumetric_fog" in app.graph.compile().kept
    app.close()


@pytest.mark.parametrize("froxels", [None, (40, 24, 32)])
def test_the_light_shafts_march_is_a_compute_dispatch_into_a_storage_target(gpu, froxels):
    """Per texel: the march and the upsampling composite (dispatches) and the low-res far depth (a draw);
    from froxels: the volume's fill, its history's resolve and the per-pixel apply, no draw."""
    from atmos.gpu.gl_meter import GLMeter
    from atmos.plugins.light_shafts import LightShaftsPlugin
    runs = []
    for plugins in ((), (LightShaftsPlugin(mode="march", froxels=froxels),)):
        app = atmos.App(gpu).add_plugins(atmos.DefaultPlugins(overlay=False), *plugins)
        app.update(1 / 60)
        with GLMeter() as meter:
            app.update(1 / 60)
        runs.append((meter.calls["ComputeShader.run"], meter.calls["VertexArray.render"]))
        dump = app.graph.dump()
        app.close()
    assert runs[1][0] == runs[0][0] + (2 if froxels is None else 3)
    assert runs[1][1] == runs[0][1] + (1 if froxels is None else 0)
    target = "light_shafts_march  transient" if froxels is None else "light_shafts_volume  transient 40x24x33"
    assert target in dump and "storage" in dump, dump


def test_pending_bits_follow_writes_and_barriers_on_random_sequences(gpu, ctx, rng):
    """Hazards' bookkeeping (each issued bit touches only the entries that still hold it) against a
    plain model: a storage write makes every use of its kind pending, a barrier clears its bits from
    every object, a use asks for exactly the pending bits its kind of use needs; objects released and
    dropped leave nothing behind."""
    hazards = Hazards(ctx)
    objects = [ctx.buffer(reserve=16) for _ in range(4)] + [ctx.texture((2, 2), 1, dtype="f4") for _ in range(4)]
    kinds = ["buffer"] * 4 + ["texture"] * 4
    every = {kind: {bit for bit in (1 << i for i in range(16)) if bit & sum(
        barrier_bit(kind, a) for a in ("sampled", "storage", "attachment", "copy", "indirect", "uniform", "vertex"))}
        for kind in ("buffer", "texture")}
    model = [set() for _ in objects]
    accesses = ("sampled", "storage", "attachment", "copy", "indirect", "uniform", "vertex")
    for _ in range(300):
        i = int(rng.integers(len(objects)))
        action = rng.integers(3)
        if action == 0:
            hazards.wrote_storage([objects[i]])
            model[i] = set(every[kinds[i]])
        elif action == 1:
            access = accesses[int(rng.integers(len(accesses)))]
            bit = barrier_bit(kinds[i], access)
            want = sum(b for b in model[i] if b & bit)
            assert hazards.use(reads=[(objects[i], access)]) == want
            for m in model:
                m -= {b for b in set(m) if b & want}
        else:
            bits = int(sum(1 << int(b) for b in rng.choice(14, size=int(rng.integers(1, 4)), replace=False)))
            hazards.issue(bits)
            for m in model:
                m -= {b for b in set(m) if b & bits}
        for obj, m in zip(objects, model):
            assert hazards.pending(obj) == bit_names(sum(m)), (hazards.pending(obj), bit_names(sum(m)))
    for obj in objects:
        obj.release()
    del objects, obj
    import gc
    gc.collect()
    hazards._purge_at = 0
    hazards.issue(moderngl.TEXTURE_FETCH_BARRIER_BIT)
    assert not hazards._dirty and not any(hazards._pending.values()), "dead objects leave no entries"
