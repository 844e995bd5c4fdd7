"""Compile a render graph: validate declarations, order passes, cull unused ones, plan texture lifetimes."""
from __future__ import annotations

from dataclasses import dataclass, field

from atmos.toposort import CycleError, stable_toposort
from atmos.graph.errors import GraphError
from atmos.graph.passes import PassBuilder, RenderPass
from atmos.graph.resources import TextureDesc


@dataclass
class ResourceInfo:
    """One resource of a compiled graph."""

    name: str
    desc: TextureDesc | None          # None for imported resources
    imported: bool
    creator: str | None = None
    writers: list[str] = field(default_factory=list)   # passes that write it (not its creator)
    readers: list[str] = field(default_factory=list)
    lifetime: tuple[int, int] | None = None            # first/last index into CompiledGraph.order; None if unused


@dataclass
class CompiledGraph:
    """The result of :func:`compile_graph`: what runs, in which order, and what was culled and why."""

    order: list[RenderPass]                        # kept passes in execution order
    sorted_names: list[str]                        # every pass in topological order (kept and culled)
    culled: dict[str, str]                         # culled pass name -> reason
    resources: dict[str, ResourceInfo]
    declarations: dict[str, PassBuilder]           # pass name -> its setup declarations
    edges: dict[tuple[str, str], str]              # ordering edge -> why it exists
    acquire: list[list[str]]                       # per kept pass: transients to acquire before it
    release: list[list[str]]                       # per kept pass: transients to release after it
    imports_used: list[str]                        # imported names the kept passes use
    declared: list[frozenset[str]] = field(default_factory=list)  # per kept pass: every name it declared

    @property
    def kept(self) -> list[str]:
        return [p.name for p in self.order]


def compile_graph(passes: list[RenderPass], imports) -> CompiledGraph:
    """Compile ``passes`` (registration order) against the imported resource names ``imports``."""
    imports = set(imports)
    builders: dict[str, PassBuilder] = {}
    for p in passes:
        builder = PassBuilder(p.name)
        p.setup(builder)
        builders[p.name] = builder
    resources = _resources(builders, imports)
    edges = _edges(passes, builders, resources)
    sorted_names = _toposort([p.name for p in passes], edges)
    kept, culled = _cull(sorted_names, builders, resources)
    by_name = {p.name: p for p in passes}
    order = [by_name[n] for n in sorted_names if n in kept]
    acquire: list[list[str]] = [[] for _ in order]
    release: list[list[str]] = [[] for _ in order]
    imports_used: list[str] = []
    for info in resources.values():
        users = [i for i, p in enumerate(order) if info.name in builders[p.name].names]
        if not users:
            continue
        info.lifetime = (users[0], users[-1])
        if info.imported:
            imports_used.append(info.name)
        else:
            acquire[users[0]].append(info.name)
            release[users[-1]].append(info.name)
    declared = [builders[p.name].names for p in order]
    return CompiledGraph(order, sorted_names, culled, resources, builders, edges, acquire, release, imports_used,
                         declared)


def _resources(builders: dict[str, PassBuilder], imports: set[str]) -> dict[str, ResourceInfo]:
    resources = {name: ResourceInfo(name, None, True) for name in sorted(imports)}
    for name, b in builders.items():
        for r, desc in b.creates.items():
            if r in imports:
                raise GraphError(f"pass '{name}' creates '{r}', but '{r}' is an imported resource; "
                                 "a pass may only read or write an imported resource")
            if r in resources:
                raise GraphError(f"passes '{resources[r].creator}' and '{name}' both create '{r}'; "
                                 "only one pass may create a resource, the others must write it")
            resources[r] = ResourceInfo(r, desc, False, creator=name)
    for name, b in builders.items():
        for kind, names in (("reads", b.reads), ("writes", b.writes)):
            for r in names:
                if r not in resources:
                    raise GraphError(f"pass '{name}' {kind} '{r}', but no pass creates '{r}' and it is not "
                                     f"imported (known resources: {', '.join(sorted(resources)) or 'none'})")
                info = resources[r]
                if info.creator == name:
                    continue
                (info.readers if kind == "reads" else info.writers).append(name)
    return resources


def _edges(passes, builders, resources) -> dict[tuple[str, str], str]:
    index = {p.name: i for i, p in enumerate(passes)}
    edges: dict[tuple[str, str], str] = {}
    succ: dict[str, set[str]] = {p.name: set() for p in passes}

    def add(a: str, b: str, why: str) -> None:
        if a != b and (a, b) not in edges:
            edges[(a, b)] = why
            succ[a].add(b)

    for p in passes:
        for other in p.before:
            if other not in index:
                raise GraphError(f"pass '{p.name}' must run before '{other}', but the graph has no pass "
                                 f"'{other}' (passes: {', '.join(index)})")
            add(p.name, other, f"'{p.name}' has before='{other}'")
        for other in p.after:
            if other not in index:
                raise GraphError(f"pass '{p.name}' must run after '{other}', but the graph has no pass "
                                 f"'{other}' (passes: {', '.join(index)})")
            add(other, p.name, f"'{p.name}' has after='{other}'")
    for info in resources.values():
        pure_readers = [r for r in info.readers if r not in info.writers]
        if info.creator:
            for user in info.writers + info.readers:
                add(info.creator, user, f"'{info.creator}' creates '{info.name}' used by '{user}'")
        for w in info.writers:
            for r in pure_readers:
                add(w, r, f"'{r}' reads '{info.name}' written by '{w}'")
    # several writers of one resource: keep any order the edges so far imply, else registration order
    for info in resources.values():
        writers = sorted(info.writers, key=index.__getitem__)
        for i, a in enumerate(writers):
            for b in writers[i + 1:]:
                if not _reaches(succ, b, a) and not _reaches(succ, a, b):
                    add(a, b, f"'{a}' and '{b}' both write '{info.name}' (registration order)")
    return edges


def _reaches(succ: dict[str, set[str]], start: str, goal: str) -> bool:
    stack, seen = [start], {start}
    while stack:
        for n in succ[stack.pop()]:
            if n == goal:
                return True
            if n not in seen:
                seen.add(n)
                stack.append(n)
    return False


def _toposort(names: list[str], edges: dict[tuple[str, str], str]) -> list[str]:
    """Stable topological order; a cycle is a GraphError naming its passes and why each edge exists."""
    try:
        return stable_toposort(names, edges)
    except CycleError as error:
        cycle = error.cycle
        links = [(cycle[i], cycle[(i + 1) % len(cycle)]) for i in range(len(cycle))]
        raise GraphError("render graph has a cycle between passes " + ", ".join(f"'{n}'" for n in cycle)
                         + ": " + "; ".join(f"{a} -> {b} ({edges[(a, b)]})" for a, b in links)) from None


def _cull(sorted_names, builders, resources) -> tuple[set[str], dict[str, str]]:
    """Walk backwards from side effects; keep passes that produce something a kept pass needs."""
    needed: set[str] = set()
    kept: set[str] = set()
    culled_names: list[str] = []
    for name in reversed(sorted_names):
        b = builders[name]
        outputs = set(b.creates) | set(b.writes)
        side_effect = b.has_side_effect or any(resources[w].imported for w in b.writes)
        if side_effect or outputs & needed:
            kept.add(name)
            needed |= set(b.reads)
            needed -= set(b.creates)
        else:
            culled_names.append(name)
    culled: dict[str, str] = {}
    for name in reversed(culled_names):
        b = builders[name]
        outputs = list(b.creates) + [w for w in b.writes if w not in b.creates]
        if not outputs:
            culled[name] = "declares no outputs and no side effect"
            continue
        reasons = []
        for r in outputs:
            readers = [p for p in resources[r].readers if p != name]
            if readers:
                reasons.append(f"only culled passes read texture '{r}' ({', '.join(readers)})")
            else:
                reasons.append(f"nothing reads texture '{r}'")
        culled[name] = "; ".join(reasons)
    return kept, culled
