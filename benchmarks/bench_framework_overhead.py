"""Per-frame framework overhead: schedule + esper queries + render-graph execute, GPU work empty.

500 weather-like entities are updated by three systems (weather rules, wind, lifetime) and the
render graph runs eight passes that declare transient textures but draw nothing. Goal: < 1 ms per
frame on the 2-core CI machine.

Second: the render graph's per-frame setup on a full scene (the sunset demo: sky, terrain, clouds,
cloud shadows, cloud sprites, light shafts, overlay): ``RenderGraph.compile()`` runs each pass's
``setup`` (but those whose ``setup_key`` is unchanged) and compiles again only when a declaration changed; its steady cost is printed
beside one full compile (what recompiling every frame would cost).

Run: .venv/bin/python -m pytest -s benchmarks/bench_framework_overhead.py
"""
import time
from dataclasses import dataclass

from atmos.app import App
from atmos.gpu import create_headless
from atmos.graph import RenderPass, TextureDesc

ENTITIES = 500
GOAL_MS = 1.0


@dataclass(slots=True)
class Ellipsoid:
    x: float
    y: float
    z: float
    rx: float = 4.0
    ry: float = 2.0
    rz: float = 4.0


@dataclass(slots=True)
class Motion:
    vx: float = 0.1
    vz: float = 0.05


@dataclass(slots=True)
class Life:
    age: float = 0.0
    lifetime: float = 1e9


def weather(app):
    for _, (e, life) in app.world.get_components(Ellipsoid, Life):
        life.age += app.clock.dt
        if life.age > life.lifetime - 5.0:
            e.rx *= 0.99


def wind(app):
    for _, (e, m) in app.world.get_components(Ellipsoid, Motion):
        e.x += m.vx
        e.z += m.vz


def cover(app):
    app.cover = sum(1 for _ in app.world.get_component(Ellipsoid))


class EmptyPass(RenderPass):
    phase = "post"

    def __init__(self, name, reads, creates, side_effect=False):
        self.name, self.reads, self.creates, self.keep = name, reads, creates, side_effect

    def setup(self, b):
        for r in self.reads:
            b.read(r)
        for c in self.creates:
            b.create(c, TextureDesc((64, 64)))
        if self.keep:
            b.side_effect()

    def execute(self, frame):
        for r in self.reads:
            frame.resource(r)


def make_app(gpu):
    app = App(gpu)
    for i in range(ENTITIES):
        app.world.create_entity(Ellipsoid(i * 0.1, 5.0, i * 0.2), Motion(), Life(lifetime=1000.0 + i))
    app.add_system(weather, "update", label="weather")
    app.add_system(wind, "update", label="wind", after="weather")
    app.add_system(cover, "update", label="cover", after="wind")
    names = [f"p{i}" for i in range(8)]
    for i, name in enumerate(names):
        reads = [f"t{i - 1}"] if i else []
        app.graph.add_pass(EmptyPass(name, reads, [f"t{i}"], side_effect=(i == len(names) - 1)))
    app.startup()
    app.run_frames(5)
    return app


def test_framework_overhead(benchmark):
    gpu = create_headless((64, 64))
    app = make_app(gpu)
    allocations = app.graph.pool.allocations
    benchmark.pedantic(app.update, args=(1 / 60,), rounds=300, iterations=1, warmup_rounds=20)
    mean_ms = benchmark.stats.stats.mean * 1000
    median_ms = benchmark.stats.stats.median * 1000
    print(f"\nframework overhead, {ENTITIES} entities, 8 passes: mean {mean_ms:.3f} ms, "
          f"median {median_ms:.3f} ms per frame (goal < {GOAL_MS} ms): {'met' if median_ms < GOAL_MS else 'MISSED'}")
    assert app.graph.pool.allocations == allocations, "steady state must allocate no textures"
    app.close()
    gpu.release()


SETUP_GOAL_MS = 0.1  # per-frame setup + declaration check: a small part of the 1 ms framework budget


def full_scene(gpu):
    """The sunset demo (the fullest scene), headless, at the small size of ``gpu``."""
    from atmos.demo_registry import DemoSettings
    from atmos.runner import build_app
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True), gpu)
    app.run_frames(3)
    return app


def test_graph_setup_per_frame(benchmark):
    from atmos.graph.compiler import compile_graph
    gpu = create_headless((64, 40))
    app = full_scene(gpu)
    graph = app.graph
    compiles = graph.compiles
    benchmark.pedantic(graph.compile, rounds=500, iterations=1, warmup_rounds=20)
    median_ms = benchmark.stats.stats.median * 1000
    mean_ms = benchmark.stats.stats.mean * 1000
    assert graph.compiles == compiles, "steady frames must not recompile the graph"
    passes = list(graph.passes)
    rounds = 50
    start = time.perf_counter()
    for _ in range(rounds):
        compile_graph(passes, graph.declare(), graph._imports)
    full_ms = (time.perf_counter() - start) / rounds * 1000
    compiled = graph.compile()
    print(f"\nrender-graph setup per frame, full scene ({len(passes)} passes, {len(compiled.kept)} kept): "
          f"mean {mean_ms:.3f} ms, median {median_ms:.3f} ms (goal < {SETUP_GOAL_MS} ms): "
          f"{'met' if median_ms < SETUP_GOAL_MS else 'MISSED'}; a full compile every frame would cost "
          f"{full_ms:.3f} ms ({full_ms / median_ms:.1f}x)")
    app.close()
    gpu.release()
