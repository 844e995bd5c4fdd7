"""Render graph: ordering, validation, culling, transient texture pooling, a real GPU frame, timings, dumps."""
import time

import numpy as np
import pytest

from atmos.graph import GraphError, PassContext, RenderGraph, RenderPass, TextureDesc, TexturePool
from atmos.gpu.uniforms import bind_textures

VERT = "lib/fullscreen.vert"
SMALL = TextureDesc((8, 8))


class P(RenderPass):
    """A configurable test pass that records what the graph does with it."""

    def __init__(self, name, creates=None, reads=(), writes=(), side=False, before=(), after=(),
                 shader=None, run=None, phase="post", at=None):
        self.name, self.phase, self.before, self.after = name, phase, tuple(before), tuple(after)
        self.creates, self.reads, self.writes, self.side = dict(creates or {}), reads, writes, side
        self.shader, self.run, self.at = shader, run, dict(at or {})
        self.setups = self.prepared = self.executed = self.released = 0
        self.program = None
        self.seen = {}

    def setup(self, builder):
        self.setups += 1
        for name, desc in self.creates.items():
            builder.create(name, desc)
        for name in self.reads:
            builder.read(name, at=self.at.get(name))
        for name in self.writes:
            builder.write(name)
        if self.side:
            builder.side_effect()

    def prepare(self, gpu):
        self.prepared += 1
        if self.shader:
            self.program = gpu.program(vertex_shader=VERT, fragment_shader=self.shader)

    def execute(self, frame):
        self.executed += 1
        self.seen = {n: frame.resource(n) for n in [*self.creates, *self.reads, *self.writes]}
        if self.run:
            self.run(self, frame)

    def release(self):
        self.released += 1


@pytest.fixture
def screen(ctx):
    """A small imported texture standing in for the screen."""
    texture = ctx.texture((8, 8), 4)
    yield texture
    texture.release()


@pytest.fixture
def graph(gpu, ctx):
    g = RenderGraph(gpu)
    yield g
    g.release()


def names(compiled):
    return compiled.kept


# -- ordering ----------------------------------------------------------------------------------
def test_order_follows_phases_then_data_then_names(graph):
    graph.import_resource("screen", object())
    graph.add_pass(P("present", reads=["b"], writes=["screen"], phase="present"))
    graph.add_pass(P("second", reads=["a"], creates={"b": SMALL}, phase="sky"))
    graph.add_pass(P("first", creates={"a": SMALL}, phase="sky"))
    graph.add_pass(P("hud", reads=["screen"], writes=["screen"], phase="overlay"))
    graph.add_pass(P("zeta", side=True, phase="clear"))
    graph.add_pass(P("alpha", side=True, phase="clear"))
    assert names(graph.compile()) == ["alpha", "zeta", "first", "second", "present", "hud"]


def test_overwriters_then_modifiers_then_readers_inside_a_phase(graph):
    graph.add_pass(P("make", creates={"x": SMALL}, phase="clear"))
    graph.add_pass(P("reader", reads=["x"], side=True))
    graph.add_pass(P("blend", reads=["x"], writes=["x"]))     # modifies: reads and writes
    graph.add_pass(P("paint", writes=["x"]))                  # overwrites
    compiled = graph.compile()
    assert names(compiled) == ["make", "paint", "blend", "reader"]
    assert compiled.reads["blend"] == {"x": 2} and compiled.writes["blend"] == {"x": 3}
    assert compiled.reads["reader"] == {"x": 3}
    assert compiled.resources["x"].versions == ["make", "paint", "blend"]


def test_two_unordered_writers_in_one_phase_are_an_error_naming_both(graph):
    graph.add_pass(P("make", creates={"x": SMALL}, phase="clear"))
    graph.add_pass(P("fog", reads=["x"], writes=["x"], side=True, phase="media"))
    graph.add_pass(P("haze", reads=["x"], writes=["x"], side=True, phase="media"))
    with pytest.raises(GraphError, match=r"passes 'fog' and 'haze' both modify 'x' in phase 'media'.*after=") :
        graph.compile()
    graph.remove_pass("haze")
    graph.add_pass(P("haze", reads=["x"], writes=["x"], side=True, phase="media", after=["fog"]))
    assert names(graph.compile()) == ["make", "fog", "haze"]
    graph.add_pass(P("sky1", writes=["x"], side=True, phase="sky"))
    graph.add_pass(P("sky2", writes=["x"], side=True, phase="sky"))
    with pytest.raises(GraphError, match=r"'sky1' and 'sky2' both overwrite 'x' in phase 'sky'"):
        graph.compile()


def test_two_passes_of_one_exclusive_group_may_not_both_be_on(graph):
    graph.add_pass(P("make", creates={"x": SMALL}, phase="clear"))
    a, b = P("a", reads=["x"], writes=["x"], side=True), P("b", reads=["x"], writes=["x"], side=True, after=["a"])
    a.exclusive = b.exclusive = "look"
    graph.add_pass(a)
    graph.add_pass(b)
    with pytest.raises(GraphError, match=r"passes 'a' and 'b' are alternatives \(exclusive group 'look'\).*"
                                         r"configure\(enabled=False\)"):
        graph.compile()                     # even though after= orders them
    b.reads = b.writes = ()
    b.side = False                          # b is off: declares nothing
    assert names(graph.compile()) == ["make", "a"]


def test_opaque_writers_commute_in_name_order(graph):
    graph.add_pass(P("make", creates={"x": SMALL}, phase="clear"))
    graph.add_pass(P("terrain", reads=["x"], writes=["x"], side=True, phase="opaque"))
    graph.add_pass(P("ground", reads=["x"], writes=["x"], side=True, phase="opaque"))
    assert names(graph.compile()) == ["make", "ground", "terrain"]


def test_order_never_depends_on_registration(gpu, rng):
    specs = [("make", dict(creates={"x": SMALL}, phase="clear")), ("sky", dict(writes=["x"], phase="sky")),
             ("layer", dict(reads=["x"], writes=["x"], phase="sky")),
             ("b_mesh", dict(writes=["x"], phase="opaque")), ("a_mesh", dict(writes=["x"], phase="opaque")),
             ("fog", dict(reads=["x"], writes=["x"], phase="media")), ("show", dict(reads=["x"], side=True))]
    orders = set()
    for perm in [specs, specs[::-1]] + [[specs[i] for i in rng.permutation(len(specs))] for _ in range(60)]:
        g = RenderGraph(gpu)
        for name, kw in perm:
            g.add_pass(P(name, **kw))
        orders.add(tuple(g.compile().kept))
    assert orders == {("make", "sky", "layer", "a_mesh", "b_mesh", "fog", "show")}


def test_versioned_read_of_an_earlier_phase(graph):
    graph.add_pass(P("make", creates={"x": SMALL}, phase="clear"))
    graph.add_pass(P("cloud", reads=["x"], writes=["x"], side=True, phase="translucent"))
    graph.add_pass(P("mask", reads=["x"], side=True, phase="translucent", at={"x": "opaque"}))
    compiled = graph.compile()
    assert names(compiled) == ["make", "mask", "cloud"]       # the read of version 1 runs before version 2
    assert compiled.reads["mask"] == {"x": 1}
    graph.add_pass(P("fog", reads=["x"], writes=["x"], phase="media"))
    graph.add_pass(P("late", reads=["x"], side=True, phase="post", at={"x": "translucent"}))
    with pytest.raises(GraphError, match=r"'late' \(phase 'post'\) reads 'x' as of phase 'translucent', "
                                         r"but 'fog' writes it in between"):
        graph.compile()
    graph.remove_pass("late")
    graph.add_pass(P("early", reads=["x"], side=True, phase="sky", at={"x": "post"}))
    with pytest.raises(GraphError, match="later phase 'post'"):
        graph.compile()


def test_phase_is_required_and_checked(graph):
    with pytest.raises(GraphError, match=r"pass 'nophase' .* has phase ''.*one of: clear, sky"):
        graph.add_pass(P("nophase", phase=""))
    with pytest.raises(GraphError, match="has phase 'later'"):
        graph.add_pass(P("bad", phase="later"))


def test_hints_across_phases_must_agree_with_them(graph):
    graph.add_pass(P("sky", side=True, phase="sky", after=["fog"]))
    graph.add_pass(P("fog", side=True, phase="media"))
    with pytest.raises(GraphError, match=r"'sky' has after='fog'.*phases run in the order"):
        graph.compile()


def test_setup_runs_every_frame_and_recompiles_only_on_change(gpu, graph):
    sizes = []
    wanted = [(8, 8)]

    class Sized(P):
        def setup(self, builder):
            self.setups += 1
            builder.create("c", TextureDesc(wanted[0]))
            builder.side_effect()

    sized = graph.add_pass(Sized("sized", run=lambda p, f: sizes.append(f.resource("c").size)))
    first = graph.compile()
    assert graph.compile() is first and sized.setups == 2 and graph.compiles == 1
    wanted[0] = (4, 4)
    graph.execute()
    assert graph.compile() is not first and graph.compiles == 2 and sizes == [(4, 4)]
    graph.add_pass(P("b", side=True))
    assert graph.compiles == 2 and graph.compile() and graph.compiles == 3


def test_setup_key_keeps_declarations_while_unchanged(gpu, graph):
    """A pass with a setup_key declares again only when its key changes; a new pass of the same name
    declares on its own."""
    sizes, key = [], [(8, 8)]

    class Keyed(P):
        def setup_key(self):
            return (key[0],)

        def setup(self, builder):
            self.setups += 1
            builder.create("c", TextureDesc(key[0]))
            builder.side_effect()

    keyed = graph.add_pass(Keyed("keyed", run=lambda p, f: sizes.append(f.resource("c").size)))
    for _ in range(3):
        graph.execute()
    assert keyed.setups == 1 and graph.compiles == 1 and sizes == [(8, 8)] * 3
    key[0] = (4, 4)                          # what setup reads changed: declared and compiled anew next frame
    graph.execute()
    assert keyed.setups == 2 and graph.compiles == 2 and sizes[-1] == (4, 4)
    graph.execute()
    assert keyed.setups == 2
    graph.remove_pass("keyed")
    again = graph.add_pass(Keyed("keyed", run=lambda p, f: sizes.append(f.resource("c").size)))
    graph.execute()
    assert again.setups == 1 and sizes[-1] == (4, 4)


def test_passes_with_setup_keys_follow_live_changes():
    """The App's keyed passes (clear, present, sprites, fog, shadows, camera): a setting changed live and
    a resize take effect in the next frame's declarations."""
    from atmos.demo_registry import DemoSettings
    from atmos.gpu import create_headless
    from atmos.plugins.physical_camera import PhysicalCameraPlugin
    from atmos.runner import build_app
    gpu = create_headless((64, 36))
    app = build_app("sunset", DemoSettings(size=(64, 36), headless=True, clouds="sprites"), gpu)
    try:
        app.run_frames(2, 1 / 30)
        graph = app.graph
        keyed = [p.name for p in graph.passes if p.setup_key is not None]
        assert {"clear", "present", "cloud_render", "fog", "cloud_shadows", "cloud_shadow_map"} <= set(keyed)

        def declared(name):
            return graph.compile().declarations[name]

        assert "bloom" in declared("present").reads
        camera = next(p for p in app.plugins if isinstance(p, PhysicalCameraPlugin))
        camera.configure(bloom=0.0)              # live: the present no longer reads the bloom
        app.run_frames(1, 1 / 30)
        assert "bloom" not in declared("present").reads and "bloom" not in graph.compile().kept
        camera.configure(enabled=False)
        app.run_frames(1, 1 / 30)
        assert "camera_exposure" not in declared("present").reads
        sprites = next(p for p in graph.passes if p.name == "cloud_render")
        sprites.plugin.configure(enabled=False)  # switched off: declares nothing, culled
        app.run_frames(1, 1 / 30)
        assert not declared("cloud_render").names and "cloud_render" not in graph.compile().kept
        sprites.plugin.configure(enabled=True, downsample=2)      # on again, through a low-res layer
        app.run_frames(1, 1 / 30)
        assert "cloud_color" in declared("cloud_render").creates
        gpu.resize((32, 18))                     # the frame size: the clear makes its targets at it
        app.run_frames(1, 1 / 30)
        assert declared("clear").creates["color"].size == (32, 18)
        assert declared("present").creates["present_image"].size == (32, 18)
        app.run_frames(1, 1 / 30)
    finally:
        app.close()
        gpu.release()


def test_a_subclass_overriding_setup_does_not_inherit_the_key(graph):
    class Keyed(P):
        def setup_key(self):
            return ()

    class Overrides(Keyed):
        def setup(self, builder):
            self.setups += 1
            builder.side_effect()

    keyed, overrides = graph.add_pass(Keyed("keyed", side=True)), graph.add_pass(Overrides("overrides"))
    for _ in range(3):
        graph.compile()
    assert keyed.setups == 1 and overrides.setups == 3


def test_setup_key_follows_an_import_that_appears_or_goes(graph):
    from atmos.plugins.clouds.light.ground import GroundSunPass
    from atmos.plugins.clouds.volume.sets import CLOUD_SETS
    ground = graph.add_pass(GroundSunPass(graph))
    assert not graph.compile().declarations[ground.name].names
    graph.import_resource(CLOUD_SETS, object())
    assert CLOUD_SETS in graph.compile().declarations[ground.name].reads
    graph.remove_import(CLOUD_SETS)
    assert not graph.compile().declarations[ground.name].names


def test_cycle_names_the_passes(graph):
    graph.add_pass(P("a", creates={"x": SMALL}, side=True, after=["c"]))
    graph.add_pass(P("b", reads=["x"], creates={"y": SMALL}))
    graph.add_pass(P("c", reads=["y"], side=True))
    graph.add_pass(P("bystander", side=True))
    with pytest.raises(GraphError, match="cycle") as info:
        graph.compile()
    message = str(info.value)
    assert all(f"'{n}'" in message for n in "abc") and "bystander" not in message
    assert "after='c'" in message  # says which edge closes it


def test_hint_cycle_and_unknown_hint(graph):
    graph.add_pass(P("a", side=True, before=["b"]))
    graph.add_pass(P("b", side=True, before=["a"]))
    with pytest.raises(GraphError, match=r"cycle in phase 'post' between passes '(a|b)', '(a|b)'"):
        graph.compile()
    graph.remove_pass("b")
    graph.add_pass(P("b", side=True, after=["ghost"]))
    with pytest.raises(GraphError, match=r"'b' must run after 'ghost'.*no pass 'ghost'"):
        graph.compile()


# -- validation ---------------------------------------------------------------------------------
def test_reading_an_unknown_resource_is_an_error(graph):
    graph.add_pass(P("fog", reads=["depth"], side=True))
    with pytest.raises(GraphError, match=r"pass 'fog' reads 'depth'.*no pass creates"):
        graph.compile()


def test_writing_an_unknown_resource_is_an_error(graph):
    graph.add_pass(P("fog", writes=["color"]))
    with pytest.raises(GraphError, match=r"pass 'fog' writes 'color'.*no pass creates"):
        graph.compile()


def test_two_creators_is_an_error(graph):
    graph.add_pass(P("sky", creates={"color": SMALL}))
    graph.add_pass(P("clouds", creates={"color": SMALL}))
    with pytest.raises(GraphError, match=r"'sky' and 'clouds' both create 'color'"):
        graph.compile()


def test_creating_an_imported_name_is_an_error(graph):
    graph.import_resource("screen", object())
    graph.add_pass(P("sky", creates={"screen": SMALL}))
    with pytest.raises(GraphError, match=r"'sky' creates 'screen'.*imported"):
        graph.compile()


def test_duplicate_and_missing_pass_names(graph):
    graph.add_pass(P("sky"))
    with pytest.raises(GraphError, match="already has a pass named 'sky'"):
        graph.add_pass(P("sky"))
    with pytest.raises(GraphError, match="no name"):
        graph.add_pass(P(""))
    with pytest.raises(GraphError, match="no pass 'fog'"):
        graph.remove_pass("fog")


def test_texture_desc_validation():
    assert TextureDesc([4, 4]).size == (4, 4) and TextureDesc((4, 4)) == TextureDesc([4, 4])
    assert hash(TextureDesc((4, 4, 4), 1, "f4")) == hash(TextureDesc((4, 4, 4), 1, "f4"))
    with pytest.raises(ValueError, match=r"\(w, h\) or \(w, h, d\)"):
        TextureDesc((4,))
    with pytest.raises(ValueError, match=r"\(w, h\) or \(w, h, d\)"):
        TextureDesc((0, 4))
    with pytest.raises(ValueError, match="1, 2, 3 or 4"):
        TextureDesc((4, 4), components=5)
    with pytest.raises(ValueError, match="one of f1, f2, f4"):
        TextureDesc((4, 4), dtype="f8")
    with pytest.raises(ValueError, match="'linear' or 'nearest'"):
        TextureDesc((4, 4), filter="cubic")
    with pytest.raises(ValueError, match="depth.*2D"):
        TextureDesc((4, 4, 4), depth=True)
    with pytest.raises(ValueError, match="filter='nearest'"):
        TextureDesc((4, 4), 1, "u4")
    TextureDesc((4, 4), 1, "u4", filter="nearest")


# -- culling ------------------------------------------------------------------------------------
def test_unread_chain_is_culled_wholly(graph, screen):
    graph.import_resource("screen", screen)
    graph.add_pass(P("noise", creates={"noise": SMALL}))
    graph.add_pass(P("fog", reads=["noise"], creates={"fog_color": SMALL}))
    graph.add_pass(P("sky", writes=["screen"]))
    compiled = graph.compile()
    assert names(compiled) == ["sky"]
    assert set(compiled.culled) == {"noise", "fog"}
    assert compiled.culled["fog"] == "nothing reads texture 'fog_color'"
    assert "only culled passes read texture 'noise' (fog)" in compiled.culled["noise"]


def test_chain_feeding_a_kept_pass_is_kept(graph, screen):
    graph.import_resource("screen", screen)
    graph.add_pass(P("noise", creates={"noise": SMALL}))
    graph.add_pass(P("fog", reads=["noise"], creates={"fog_color": SMALL}))
    graph.add_pass(P("unused", reads=["noise"], creates={"junk": SMALL}))
    graph.add_pass(P("compose", reads=["fog_color"], writes=["screen"]))
    graph.add_pass(P("stats", reads=["noise"], side=True))
    compiled = graph.compile()
    assert names(compiled) == ["noise", "fog", "compose", "stats"]
    assert list(compiled.culled) == ["unused"]


def test_writing_an_import_or_side_effect_keeps_a_pass(graph, screen):
    graph.import_resource("screen", screen)
    graph.import_resource("history", screen)
    graph.add_pass(P("to_screen", writes=["screen"]))
    graph.add_pass(P("reads_import_only", reads=["history"]))
    graph.add_pass(P("debug", side=True))
    compiled = graph.compile()
    assert names(compiled) == ["debug", "to_screen"]
    assert compiled.culled == {"reads_import_only": "declares no outputs and no side effect"}


def test_culled_passes_compile_no_shaders_and_allocate_no_textures(gpu, graph, screen):
    odd = TextureDesc((3, 5), 2, "f4")  # a desc no kept pass uses
    graph.import_resource("screen", screen)
    culled = graph.add_pass(P("culled", creates={"fog_color": odd}, shader="test/graph_culled.frag"))
    kept = graph.add_pass(P("kept", creates={"tmp": SMALL}, shader="test/graph_gradient.frag"))
    graph.add_pass(P("present", reads=["tmp"], writes=["screen"]))
    for _ in range(3):
        graph.execute()
    assert "test/graph_culled.frag" not in gpu.compiled_files
    assert "test/graph_gradient.frag" in gpu.compiled_files
    assert culled.prepared == culled.executed == 0
    assert kept.prepared == 1 and kept.executed == 3
    assert graph.pool.allocations == 1 and graph.pool.in_use == 0
    assert odd.key not in graph.pool._free


# -- transient textures ---------------------------------------------------------------------------
def test_pool_reuses_equal_descs(gpu, ctx):
    pool = TexturePool(gpu)
    a = pool.acquire(SMALL)
    b = pool.acquire(SMALL)
    assert a is not b and pool.allocations == 2
    pool.release(a)
    assert pool.acquire(SMALL) is a and pool.allocations == 2
    c = pool.acquire(TextureDesc((8, 8), filter="nearest"))
    assert c is not a and pool.allocations == 3
    volume = pool.acquire(TextureDesc((4, 4, 4), 1, "f4"))
    depth = pool.acquire(TextureDesc((8, 8), depth=True))
    assert volume.size == (4, 4, 4) and volume.components == 1 and depth.depth
    stranger = ctx.texture((1, 1), 1)
    with pytest.raises(ValueError, match="not acquired from this pool"):
        pool.release(stranger)
    stranger.release()
    pool.release(b)
    with pytest.raises(ValueError, match="already released"):
        pool.release(b)
    pool.release_all()
    assert pool.textures == 0 and pool.in_use == 0
    assert all(type(t.mglo).__name__ == "InvalidObject" for t in (a, b, c, volume, depth))


def test_steady_frames_allocate_nothing(graph, screen):
    graph.import_resource("screen", screen)
    graph.add_pass(P("a", creates={"x": SMALL}))
    graph.add_pass(P("b", reads=["x"], creates={"y": SMALL}))
    graph.add_pass(P("c", reads=["x", "y"], writes=["screen"]))
    graph.execute()
    first = graph.pool.allocations
    assert first == 2  # x and y overlap: two textures
    for _ in range(20):
        graph.execute()
        assert graph.pool.in_use == 0
    assert graph.pool.allocations == first


def test_textures_with_disjoint_lifetimes_alias(graph, screen):
    other = TextureDesc((8, 8), 1, "f4")
    graph.import_resource("screen", screen)
    p1 = graph.add_pass(P("p1", creates={"a": SMALL}))
    p2 = graph.add_pass(P("p2", reads=["a"], creates={"mid": other}))
    p3 = graph.add_pass(P("p3", reads=["mid"], creates={"b": SMALL}))
    p4 = graph.add_pass(P("p4", reads=["b"], writes=["screen"]))
    compiled = graph.compile()
    assert compiled.resources["a"].lifetime == (0, 1) and compiled.resources["b"].lifetime == (2, 3)
    graph.execute()
    assert p1.seen["a"] is p2.seen["a"] and p3.seen["b"] is p4.seen["b"]
    assert p1.seen["a"] is p3.seen["b"]  # same desc, lifetimes don't overlap: one texture
    assert p2.seen["mid"] is not p1.seen["a"]
    assert graph.pool.allocations == 2


def test_undeclared_texture_is_an_error(graph, screen):
    def peek(p, frame):
        frame.resource("screen")
    graph.add_pass(P("sneaky", side=True, run=peek))
    graph.import_resource("screen", screen)
    with pytest.raises(GraphError, match="'sneaky' uses 'screen' but did not declare it"):
        graph.execute()


# -- a real frame -----------------------------------------------------------------------------------
def _fill(p, frame):
    frame.framebuffer(color=["color"]).use()
    frame.fullscreen(p.program)


def _swizzle(p, frame):
    bind_textures(p.program, src=frame.resource("color"))
    frame.framebuffer(color=["target"]).use()
    frame.fullscreen(p.program)


def test_two_pass_frame_renders_expected_pixels(gpu, graph):
    w, h = gpu.size
    graph.import_resource("target", lambda: gpu.target)
    graph.add_pass(P("gradient", creates={"color": TextureDesc((w, h))},
                     shader="test/graph_gradient.frag", run=_fill))
    graph.add_pass(P("swizzle", reads=["color"], writes=["target"],
                     shader="test/graph_swizzle.frag", run=_swizzle))
    gpu.target.clear(0.0, 0.0, 0.0, 1.0)
    graph.execute()
    pixels = gpu.read_pixels().astype(int)  # (h, w, rgb), top row first
    ramp = (np.arange(w) + 0.5) / w  # v_uv.x at pixel centres
    expected = np.empty((h, w, 3))
    expected[..., 0] = 0.5            # blue of the gradient
    expected[..., 1] = ramp[None, :]  # red ramp moved to green
    expected[..., 2] = 0.5            # green 0.25 doubled
    assert np.abs(pixels - np.round(expected * 255)).max() <= 1
    assert pixels[0, 0, 1] <= 1 and pixels[0, -1, 1] >= 254


def test_callable_import_is_resolved_every_frame(gpu, graph, ctx):
    red, green = ctx.texture((4, 4), 4), ctx.texture((4, 4), 4)
    red.write(np.tile([255, 0, 0, 255], 16).astype(np.uint8).tobytes())
    green.write(np.tile([0, 255, 0, 255], 16).astype(np.uint8).tobytes())
    out = ctx.texture((4, 4), 4)
    current = [red]

    def copy(p, frame):
        fbo = frame.framebuffer(color=["out"])
        ctx.copy_framebuffer(fbo, frame.framebuffer(color=["src"]))

    graph.import_resource("src", lambda: current[0])
    graph.import_resource("out", out)
    copier = graph.add_pass(P("copy", reads=["src"], writes=["out"], run=copy))
    compiled = graph.compile()
    graph.execute()
    assert copier.seen["src"] is red
    assert np.frombuffer(out.read(), np.uint8)[:4].tolist() == [255, 0, 0, 255]
    current[0] = green
    graph.execute()
    assert copier.seen["src"] is green and graph.compile() is compiled and graph.compiles == 1
    assert np.frombuffer(out.read(), np.uint8)[:4].tolist() == [0, 255, 0, 255]
    graph.import_resource("src", red)  # replacing a known import's source does not recompile either
    graph.execute()
    assert copier.seen["src"] is red and graph.compile() is compiled
    graph.release()
    for texture in (red, green, out):
        texture.release()


def test_the_scene_view_reaches_passes(graph):
    got = {}

    def grab(p, frame):
        assert isinstance(frame, PassContext)
        got.update(view=frame.view, name=frame.pass_name, gpu=frame.gpu)

    graph.add_pass(P("grab", side=True, run=grab))
    graph.execute("the view")
    assert got == {"view": "the view", "name": "grab", "gpu": graph.gpu}


def test_framebuffers_are_cached(graph, screen):
    fbos = []
    graph.import_resource("screen", screen)
    graph.add_pass(P("draw", creates={"c": SMALL, "d": TextureDesc((8, 8), depth=True)}, writes=["screen"],
                     run=lambda p, f: fbos.append((f.framebuffer(["c"], depth="d"), f.framebuffer(["screen"])))))
    for _ in range(4):
        graph.execute()
    assert len({id(a) for a, _ in fbos}) == 1 and len({id(b) for _, b in fbos}) == 1
    assert fbos[0][0] is not fbos[0][1]


# -- timings, dumps, lifetime --------------------------------------------------------------------
def test_timings_cover_kept_passes_only(graph, screen):
    graph.timings_enabled = True
    graph.import_resource("screen", screen)
    graph.add_pass(P("a", creates={"x": SMALL}))
    graph.add_pass(P("b", reads=["x"], writes=["screen"]))
    graph.add_pass(P("culled", creates={"y": SMALL}))
    deadline = time.monotonic() + 10.0
    frame = 0
    while time.monotonic() < deadline:   # results are read once in: fast frames on a loaded machine run ahead of them
        graph.execute()
        frame += 1
        if frame > 4 and len(graph.timings) >= 2:
            break
    assert set(graph.timings) == {"a", "b"}
    for gpu_ms, cpu_ms in graph.timings.values():
        assert gpu_ms >= 0.0 and cpu_ms >= 0.0
    graph.remove_pass("b")
    graph.add_pass(P("b2", reads=["x"], writes=["screen"]))
    graph.compile()
    assert "b" not in graph.timings
    graph.timings_enabled = False
    before = dict(graph.timings)
    for _ in range(4):
        graph.execute()
    assert graph.timings == before


def test_dump_and_dot_show_kept_and_culled(graph, screen):
    graph.import_resource("screen", screen)
    graph.add_pass(P("sky", creates={"sky_color": TextureDesc((64, 32))}))
    graph.add_pass(P("fog", reads=["sky_color"], creates={"fog_color": SMALL}))
    graph.add_pass(P("present", reads=["sky_color"], writes=["screen"]))
    text = graph.dump()
    assert "[post]" in text and "1. sky" in text and "2. present" in text
    assert "creates sky_color@1" in text and "reads sky_color@1; writes screen@1 [side effect]" in text
    assert "(tests/test_render_graph.py:" in text          # each pass leads to its file
    assert "versions @0 (imported), @1 present" in text
    assert "culled:" in text and "fog" in text and "nothing reads texture 'fog_color'" in text
    assert "64x32 4xf2 linear" in text and "imported" in text and "never allocated" in text
    dot = graph.to_dot()
    assert dot.startswith("digraph") and dot.rstrip().endswith("}")
    assert '"pass:sky" [shape=box' in dot and 'label="1. sky"' in dot
    assert '"pass:fog" [shape=box, style="dashed,filled"' in dot
    assert 'subgraph "cluster_post" { label="post"' in dot
    assert "peripheries=2" in dot and '"res:sky_color@1" [shape=ellipse' in dot
    assert '"pass:sky" -> "res:sky_color@1" [label="create"]' in dot
    assert '"res:sky_color@1" -> "pass:present" [label="read"]' in dot
    assert '"pass:present" -> "res:screen@1" [label="write"]' in dot


def test_release_frees_everything(gpu, ctx, screen):
    graph = RenderGraph(gpu)
    graph.import_resource("screen", screen)
    fbos = []
    a = graph.add_pass(P("a", creates={"x": SMALL}, shader="test/graph_gradient.frag",
                         run=lambda p, f: (fbos.append(f.framebuffer(["x"])), f.framebuffer(["x"]).use(),
                                           f.fullscreen(p.program))))
    b = graph.add_pass(P("b", reads=["x"], writes=["screen"]))
    culled = graph.add_pass(P("culled", creates={"y": SMALL}))
    for _ in range(3):
        graph.execute()
    texture = a.seen["x"]
    graph.release()
    assert a.released == b.released == 1 and culled.released == 0  # never prepared: nothing to release
    assert graph.pool.textures == 0 and graph.timings == {}
    released = type(texture.mglo)
    assert released.__name__ == "InvalidObject" and type(fbos[0].mglo).__name__ == "InvalidObject"
    graph.execute()  # still usable: passes are prepared again
    assert a.prepared == 2 and graph.pool.allocations == 2
    graph.release()


def test_remove_pass_releases_it(graph):
    p = graph.add_pass(P("a", side=True))
    graph.execute()
    graph.remove_pass("a")
    assert p.released == 1 and graph.compile().kept == []


def test_every_pass_starts_from_the_same_gl_state(gpu, graph, ctx):
    """A pass that leaves blending, depth test, culling, point size, a small viewport, a scissor and
    masked writes behind: the next pass still fills the whole target with exactly its colour."""
    import moderngl
    target = ctx.texture((16, 16), 4, dtype="f4")
    depth = ctx.depth_texture((16, 16))
    graph.import_resource("t", target)
    graph.import_resource("d", depth)

    def mess(p, frame):
        fbo = frame.framebuffer(color=["t"], depth="d")
        fbo.use()
        ctx.enable(moderngl.BLEND | moderngl.DEPTH_TEST | moderngl.CULL_FACE | moderngl.PROGRAM_POINT_SIZE)
        ctx.blend_func = moderngl.ZERO, moderngl.ZERO
        ctx.blend_equation = moderngl.MIN
        ctx.depth_func = "0"
        fbo.depth_mask = False
        fbo.color_mask = (False, False, False, False)
        ctx.viewport = (0, 0, 2, 2)
        ctx.scissor = (0, 0, 1, 1)

    def fill(p, frame):
        frame.framebuffer(color=["t"], depth="d").use()
        p.program["color"].value = (0.25, 0.5, 0.75, 1.0)
        frame.fullscreen(p.program)

    graph.add_pass(P("a_mess", reads=["t"], writes=["t", "d"], run=mess, phase="sky"))
    graph.add_pass(P("b_fill", reads=["t"], writes=["t", "d"], run=fill, phase="post", shader="test/solid.frag"))
    graph.execute()
    pixels = np.frombuffer(target.read(), np.float32).reshape(16, 16, 4)
    np.testing.assert_array_equal(pixels, np.broadcast_to([0.25, 0.5, 0.75, 1.0], (16, 16, 4)))
    target.release()
    depth.release()
