"""Compile a render graph: validate declarations, order passes by phase and data, version every
write, cull unused passes, plan texture lifetimes.

Ordering rules (see :mod:`atmos.graph.phases`): phases run in their fixed order. Inside a phase,
for each resource, a pass that overwrites it (writes without reading) runs before the passes that
modify it (read and write), and both run before the passes that only read it; a creator runs
before every user. ``before``/``after`` add edges inside a phase. What is still unordered runs in
name order, so registration order never decides anything. Two unordered overwriters (or
modifiers) of one resource in one phase are an error, except in a phase whose writes commute.

Versions (as in Frostbite's FrameGraph): an imported resource starts at version 0, a created one
at version 1 (its creator's write); every later write makes the next version. Each kept pass
records the version of every resource it reads and the version its writes produce.
"""
from __future__ import annotations

import inspect
from functools import lru_cache
from dataclasses import dataclass, field
from pathlib import Path

from atmos.toposort import CycleError, stable_toposort
from atmos.graph.errors import GraphError
from atmos.graph.passes import PassBuilder, RenderPass
from atmos.graph.phases import COMMUTING, PHASE_INDEX, PHASES
from atmos.graph.resources import BufferDesc, TextureDesc


@dataclass
class ResourceInfo:
    """One resource of a compiled graph."""

    name: str
    desc: TextureDesc | BufferDesc | None   # None for imported resources
    imported: bool
    creator: str | None = None
    writers: list[str] = field(default_factory=list)   # passes that write it (not its creator)
    readers: list[str] = field(default_factory=list)
    lifetime: tuple[int, int] | None = None            # first/last index into CompiledGraph.order; None if unused
    versions: list[str] = field(default_factory=list)  # versions[v]: the kept pass that made version v


@dataclass
class CompiledGraph:
    """The result of :func:`compile_graph`: what runs, in which order, and what was culled and why."""

    order: list[RenderPass]                        # kept passes in execution order
    sorted_names: list[str]                        # every pass in phase and data order (kept and culled)
    culled: dict[str, str]                         # culled pass name -> reason
    resources: dict[str, ResourceInfo]
    declarations: dict[str, PassBuilder]           # pass name -> its setup declarations
    edges: dict[tuple[str, str], str]              # ordering edge -> why it exists
    acquire: list[list[str]]                       # per kept pass: transients to acquire before it
    release: list[list[str]]                       # per kept pass: transients to release after it
    imports_used: list[str]                        # imported names the kept passes use
    declared: list[frozenset[str]] = field(default_factory=list)  # per kept pass: every name it declared
    phases: dict[str, str] = field(default_factory=dict)          # pass name -> phase
    reads: dict[str, dict[str, int]] = field(default_factory=dict)   # kept pass -> resource -> version read
    writes: dict[str, dict[str, int]] = field(default_factory=dict)  # kept pass -> resource -> version made
    sources: dict[str, str] = field(default_factory=dict)            # pass name -> "file:line" of its class
    uses: list[tuple[tuple, tuple, tuple]] = field(default_factory=list)
    # per kept pass: ((name, read access), ...), ((name, write access), ...), (names it writes as storage)
    plan: list | None = None     # what execute does around each kept pass, made by its first run

    @property
    def kept(self) -> list[str]:
        return [p.name for p in self.order]


def compile_graph(passes: list[RenderPass], builders: dict[str, PassBuilder], imports) -> CompiledGraph:
    """Compile ``passes`` (any order: it decides nothing) with their ``builders`` (the declarations
    their ``setup`` made) against the imported resource names ``imports``."""
    imports = set(imports)
    passes = sorted(passes, key=lambda p: (PHASE_INDEX[p.phase], p.name))
    phase_of = {p.name: p.phase for p in passes}
    _check_exclusive(passes, builders)
    resources = _resources(builders, imports)
    edges, conflicts = _edges(passes, builders, resources, phase_of)
    sorted_names = _order(passes, edges)
    _check_conflicts(conflicts, edges, sorted_names)
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
    reads, writes = _versions(order, builders, resources)
    declared = [builders[p.name].names for p in order]
    uses = [_uses(builders[p.name]) for p in order]
    return CompiledGraph(order, sorted_names, culled, resources, builders, edges, acquire, release, imports_used,
                         declared, phase_of, reads, writes, {p.name: source_of(p) for p in passes}, uses)


def _uses(b: PassBuilder) -> tuple[tuple, tuple, tuple]:
    """A pass's declared uses for the barriers before it and the storage writes after it."""
    reads = tuple((n, b.access.get(n, (None, None))[0]) for n in b.reads if n not in b.creates)
    writes = tuple((n, b.access.get(n, (None, None))[1]) for n in list(b.creates) + b.writes)
    return reads, writes, tuple(n for n, access in writes if access == "storage")


def source_of(p: RenderPass) -> str:
    """``file:line`` of the pass's class, relative to the folder holding the atmos package."""
    return _class_source(type(p))


@lru_cache(maxsize=None)
def _class_source(cls) -> str:
    try:
        file = Path(inspect.getsourcefile(cls))
        line = inspect.getsourcelines(cls)[1]
    except (OSError, TypeError):
        return cls.__module__
    import atmos
    root = Path(atmos.__file__).resolve().parent.parent
    try:
        file = file.resolve().relative_to(root)
    except ValueError:
        pass
    return f"{file}:{line}"


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
                                     f"imported (known resources: {', '.join(sorted(resources)) or 'none'}); "
                                     "is the plugin that provides it added?")
                info = resources[r]
                desc = info.desc
                if (kind == "writes" and b.access.get(r, (None, None))[1] == "storage"
                        and isinstance(desc, TextureDesc) and not desc.storage):
                    raise GraphError(f"pass '{name}' writes '{r}' as storage, but '{r}' was created by "
                                     f"'{info.creator}' with storage=False ({desc}); create it with "
                                     "TextureDesc(..., storage=True)")
                if info.creator == name:
                    continue
                (info.readers if kind == "reads" else info.writers).append(name)
    return resources


def _edges(passes, builders, resources, phase_of):
    """Ordering edges inside phases, and the writer pairs that must end up ordered."""
    index = PHASE_INDEX
    edges: dict[tuple[str, str], str] = {}

    def add(a: str, b: str, why: str) -> None:
        if a != b and (a, b) not in edges:
            edges[(a, b)] = why

    for p in passes:
        for kind, others in (("before", p.before), ("after", p.after)):
            for other in others:
                if other not in phase_of:
                    raise GraphError(f"pass '{p.name}' must run {kind} '{other}', but the graph has no pass "
                                     f"'{other}' (passes: {', '.join(phase_of)})")
                first, then = (p.name, other) if kind == "before" else (other, p.name)
                if index[phase_of[first]] > index[phase_of[then]]:
                    raise GraphError(f"pass '{p.name}' has {kind}='{other}', but '{first}' is in phase "
                                     f"'{phase_of[first]}', after '{then}''s phase '{phase_of[then]}'; "
                                     f"phases run in the order {', '.join(PHASES)}")
                if phase_of[first] == phase_of[then]:
                    add(first, then, f"'{p.name}' has {kind}='{other}'")
    conflicts: list[tuple[str, str, str, str, str]] = []
    for info in resources.values():
        users: dict[str, list[str]] = {}
        for name in ([info.creator] if info.creator else []) + info.writers + info.readers:
            if name not in users.setdefault(phase_of[name], []):
                users[phase_of[name]].append(name)
        if info.creator:
            for phase, names in users.items():
                if index[phase] < index[phase_of[info.creator]]:
                    raise GraphError(f"pass '{names[0]}' (phase '{phase}') uses '{info.name}', but its creator "
                                     f"'{info.creator}' runs later, in phase '{phase_of[info.creator]}'")
        for phase, names in users.items():
            over, modify, read = [], [], []
            for n in names:
                b = builders[n]
                writes = n == info.creator or info.name in b.writes
                reads = info.name in b.reads
                at = b.reads.get(info.name)
                if writes and reads and at is not None:
                    raise GraphError(f"pass '{n}' writes '{info.name}' and reads it at phase '{at}'; a pass "
                                     "that writes a resource reads its current version (leave out at=)")
                if at is not None and index[at] > index[phase]:
                    raise GraphError(f"pass '{n}' (phase '{phase}') reads '{info.name}' at the later phase "
                                     f"'{at}'; a pass can only read versions made before it runs")
                if at is not None and at != phase:
                    _check_version_kept(info, n, at, phase, phase_of)
                    for w in names:                # write-after-read: writers of this phase come after it
                        if w != n and (w == info.creator or info.name in builders[w].writes):
                            add(n, w, f"'{n}' reads '{info.name}' as of phase '{at}', before '{w}' writes it")
                    continue
                (modify if writes and reads else over if writes else read).append(n)
            for o in over:
                for later in modify + read:
                    add(o, later, f"'{later}' reads '{info.name}' after '{o}' writes it")
            for m in modify:
                for later in read:
                    add(m, later, f"'{later}' reads '{info.name}' after '{m}' modifies it")
            if phase not in COMMUTING:
                for group, verb in ((over, "overwrite"), (modify, "modify")):
                    for i, a in enumerate(group):
                        for b in group[i + 1:]:
                            conflicts.append((a, b, info.name, phase, verb))
    return edges, conflicts


def _check_version_kept(info: ResourceInfo, reader: str, at: str, phase: str, phase_of) -> None:
    """A read of the version left by phase ``at`` is an error if a pass of a phase in between writes it."""
    lo, hi = PHASE_INDEX[at], PHASE_INDEX[phase]
    for w in ([info.creator] if info.creator else []) + info.writers:
        if lo < PHASE_INDEX[phase_of[w]] < hi:
            raise GraphError(f"pass '{reader}' (phase '{phase}') reads '{info.name}' as of phase '{at}', but "
                             f"'{w}' writes it in between (phase '{phase_of[w]}'); read the current version or "
                             "move one of the passes")


def _order(passes: list[RenderPass], edges: dict[tuple[str, str], str]) -> list[str]:
    """Phase by phase, a topological order with name order for ties; a cycle is a GraphError."""
    order: list[str] = []
    for phase in PHASES:
        names = [p.name for p in passes if p.phase == phase]       # already in name order
        inside = set(names)
        local = [e for e in edges if e[0] in inside]
        try:
            order += stable_toposort(names, local)
        except CycleError as error:
            cycle = error.cycle
            links = [(cycle[i], cycle[(i + 1) % len(cycle)]) for i in range(len(cycle))]
            raise GraphError(f"render graph has a cycle in phase '{phase}' between passes "
                             + ", ".join(f"'{n}'" for n in cycle)
                             + ": " + "; ".join(f"{a} -> {b} ({edges[(a, b)]})" for a, b in links)) from None
    return order


def _check_exclusive(passes, builders) -> None:
    """A GraphError if two passes of one ``exclusive`` group both declare something this frame."""
    groups: dict[str, list[str]] = {}
    for p in passes:
        b = builders[p.name]
        if p.exclusive and (b.names or b.has_side_effect):
            groups.setdefault(p.exclusive, []).append(p.name)
    for group, names in groups.items():
        if len(names) > 1:
            raise GraphError(f"passes {' and '.join(repr(n) for n in names)} are alternatives (exclusive group "
                             f"'{group}'), but more than one is on this frame; switch all but one off "
                             "(configure(enabled=False) on its plugin, or leave the plugin out)")


def _check_conflicts(conflicts, edges, order) -> None:
    succ: dict[str, set[str]] = {n: set() for n in order}
    for a, b in edges:
        succ[a].add(b)
    for a, b, resource, phase, verb in conflicts:
        if not _reaches(succ, a, b) and not _reaches(succ, b, a):
            raise GraphError(f"passes '{a}' and '{b}' both {verb} '{resource}' in phase '{phase}' and nothing "
                             f"orders them; give one of them after=('{a}',) or before=('{a}',), let one read "
                             "what the other writes, or move one to another phase")


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


def _versions(order, builders, resources):
    """Per kept pass, the version of each resource it reads and the version each of its writes makes."""
    current = {name: (0 if info.imported else None) for name, info in resources.items()}
    for info in resources.values():
        info.versions = ["(imported)"] if info.imported else []
    reads: dict[str, dict[str, int]] = {}
    writes: dict[str, dict[str, int]] = {}
    for p in order:
        b = builders[p.name]
        reads[p.name] = {r: current[r] for r in b.reads if r not in b.creates}
        made = {}
        for r in list(b.creates) + [w for w in b.writes if w not in b.creates]:
            current[r] = 1 if r in b.creates else current[r] + 1
            resources[r].versions.append(p.name)
            made[r] = current[r]
        writes[p.name] = made
    return reads, writes


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
