"""Readable views of a compiled graph: a text dump and Graphviz dot, with phases and versions."""
from __future__ import annotations


def _describe(info) -> str:
    return "imported" if info.imported else f"transient {info.desc}"


def dump_text(compiled) -> str:
    """Execution order grouped by phase (each pass with its source file and the versions it reads
    and writes), culled passes with the reason, then resources with their versions."""
    kept = compiled.kept
    lines = [f"render graph: {len(compiled.sorted_names)} passes, {len(kept)} kept, {len(compiled.culled)} culled",
             "execution order (name@version: reads the version, writes make the next one):"]
    width = max((len(n) for n in compiled.sorted_names), default=0)
    phase = None
    for i, name in enumerate(kept, start=1):
        if compiled.phases[name] != phase:
            phase = compiled.phases[name]
            lines.append(f"  [{phase}]")
        lines.append(f"  {i:2d}. {name:<{width}}  {_uses(name, compiled)}    ({compiled.sources[name]})")
    if not kept:
        lines.append("  (nothing)")
    lines.append("culled:")
    for name, reason in compiled.culled.items():
        lines.append(f"  - {name:<{width}}  [{compiled.phases[name]}] {reason}    ({compiled.sources[name]})")
    if not compiled.culled:
        lines.append("  (nothing)")
    lines.append("resources:")
    rwidth = max((len(n) for n in compiled.resources), default=0)
    for info in compiled.resources.values():
        who = []
        if info.versions and info.lifetime:
            who.append("versions " + ", ".join(f"@{v} {p}" for v, p in enumerate(info.versions, start=0 if info.imported else 1)))
        if info.lifetime:
            first, last = info.lifetime
            who.append(f"alive in passes {first + 1}-{last + 1}")
        elif not info.imported:
            who.append("never allocated")
        else:
            who.append("unused")
        lines.append(f"  {info.name:<{rwidth}}  {_describe(info)}; {'; '.join(who)}")
    return "\n".join(lines) + "\n"


def _uses(name, compiled) -> str:
    builder = compiled.declarations[name]
    reads, writes = compiled.reads[name], compiled.writes[name]
    parts = []
    if builder.creates:
        parts.append("creates " + ", ".join(f"{r}@{writes[r]}" for r in builder.creates))
    if reads:
        parts.append("reads " + ", ".join(f"{r}@{v}" for r, v in reads.items()))
    written = [r for r in builder.writes if r not in builder.creates]
    if written:
        parts.append("writes " + ", ".join(f"{r}@{writes[r]}" for r in written))
    side = builder.has_side_effect or any(compiled.resources[w].imported for w in builder.writes)
    text = "; ".join(parts) or "(declares nothing)"
    return text + " [side effect]" if side else text


def _q(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def dump_dot(compiled) -> str:
    """Graphviz dot: one cluster per phase, passes as boxes (culled: grey, dashed; tooltip: source
    file), resource versions as ellipses (imported: doubled)."""
    kept = {name: i for i, name in enumerate(compiled.kept, start=1)}
    out = ["digraph render_graph {", "  rankdir=LR;", '  node [fontname="Helvetica"];',
           '  edge [fontname="Helvetica", fontsize=10];']
    grey = 'color="grey60", fontcolor="grey50"'
    phases: dict[str, list[str]] = {}
    for name in compiled.sorted_names:
        phases.setdefault(compiled.phases[name], []).append(name)
    for phase, names in phases.items():
        out.append(f"  subgraph {_q('cluster_' + phase)} {{ label={_q(phase)}; style=rounded; color=grey70;")
        for name in names:
            src = _q(compiled.sources[name])
            if name in kept:
                out.append(f"    {_q('pass:' + name)} [shape=box, style=filled, fillcolor=\"lightblue\", "
                           f"label={_q(f'{kept[name]}. {name}')}, tooltip={src}];")
            else:
                out.append(f"    {_q('pass:' + name)} [shape=box, style=\"dashed,filled\", fillcolor=\"grey90\", "
                           f"{grey}, label={_q(f'{name} (culled)')}, tooltip={_q(compiled.culled[name])}];")
        out.append("  }")
    for info in compiled.resources.values():
        first = 0 if info.imported else 1
        for v in range(first, first + max(len(info.versions), 1)):
            attrs = ["shape=ellipse", f"label={_q(f'{info.name}@{v}' + chr(10) + _describe(info))}"]
            if info.imported:
                attrs.append("peripheries=2")
            if info.lifetime is None:
                attrs.append(grey)
            out.append(f"  {_q(f'res:{info.name}@{v}')} [{', '.join(attrs)}];")
    for name in compiled.sorted_names:
        b = compiled.declarations[name]
        if name in kept:                    # culled passes stand alone (their tooltip says why)
            for r, v in compiled.reads[name].items():
                out.append(f"  {_q(f'res:{r}@{v}')} -> {_q('pass:' + name)} [label=\"read\"];")
            for r, v in compiled.writes[name].items():
                out.append(f"  {_q('pass:' + name)} -> {_q(f'res:{r}@{v}')} "
                           f"[label=\"{'create' if r in b.creates else 'write'}\"];")
    out.append("}")
    return "\n".join(out) + "\n"
