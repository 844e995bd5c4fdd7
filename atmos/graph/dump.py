"""Readable views of a compiled graph: a text dump and Graphviz dot."""
from __future__ import annotations


def _describe(info) -> str:
    return "imported" if info.imported else f"transient {info.desc}"


def dump_text(compiled) -> str:
    """Numbered execution order, culled passes with the reason, then resources."""
    kept = compiled.kept
    lines = [f"render graph: {len(compiled.sorted_names)} passes, {len(kept)} kept, {len(compiled.culled)} culled",
             "execution order:"]
    width = max((len(n) for n in compiled.sorted_names), default=0)
    for i, name in enumerate(kept, start=1):
        lines.append(f"  {i:2d}. {name:<{width}}  {_uses(compiled.declarations[name], compiled)}")
    if not kept:
        lines.append("  (nothing)")
    lines.append("culled:")
    for name, reason in compiled.culled.items():
        lines.append(f"  - {name:<{width}}  {reason}")
    if not compiled.culled:
        lines.append("  (nothing)")
    lines.append("resources:")
    rwidth = max((len(n) for n in compiled.resources), default=0)
    for info in compiled.resources.values():
        who = []
        if info.creator:
            who.append(f"created by {info.creator}")
        if info.writers:
            who.append(f"written by {', '.join(info.writers)}")
        if info.readers:
            who.append(f"read by {', '.join(info.readers)}")
        if info.lifetime:
            first, last = info.lifetime
            who.append(f"alive in passes {first + 1}-{last + 1}")
        elif not info.imported:
            who.append("never allocated")
        else:
            who.append("unused")
        lines.append(f"  {info.name:<{rwidth}}  {_describe(info)}; {'; '.join(who)}")
    return "\n".join(lines) + "\n"


def _uses(builder, compiled) -> str:
    parts = []
    if builder.creates:
        parts.append("creates " + ", ".join(builder.creates))
    if builder.reads:
        parts.append("reads " + ", ".join(builder.reads))
    if builder.writes:
        parts.append("writes " + ", ".join(builder.writes))
    side = builder.has_side_effect or any(compiled.resources[w].imported for w in builder.writes)
    text = "; ".join(parts) or "(declares nothing)"
    return text + " [side effect]" if side else text


def _q(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def dump_dot(compiled) -> str:
    """Graphviz dot: passes as boxes (culled: grey, dashed), resources as ellipses (imported: doubled)."""
    kept = {name: i for i, name in enumerate(compiled.kept, start=1)}
    out = ["digraph render_graph {", "  rankdir=LR;", '  node [fontname="Helvetica"];',
           '  edge [fontname="Helvetica", fontsize=10];']
    grey = 'color="grey60", fontcolor="grey50"'
    for name in compiled.sorted_names:
        if name in kept:
            out.append(f"  {_q('pass:' + name)} [shape=box, style=filled, fillcolor=\"lightblue\", "
                       f"label={_q(f'{kept[name]}. {name}')}];")
        else:
            out.append(f"  {_q('pass:' + name)} [shape=box, style=\"dashed,filled\", fillcolor=\"grey90\", {grey}, "
                       f"label={_q(f'{name} (culled)')}, tooltip={_q(compiled.culled[name])}];")
    for info in compiled.resources.values():
        attrs = ["shape=ellipse", f"label={_q(info.name + chr(10) + _describe(info))}"]
        if info.imported:
            attrs.append("peripheries=2")
        if info.lifetime is None:
            attrs.append(grey)
        out.append(f"  {_q('res:' + info.name)} [{', '.join(attrs)}];")
    for name in compiled.sorted_names:
        b = compiled.declarations[name]
        style = "" if name in kept else f", style=dashed, {grey}"
        for r in b.creates:
            out.append(f"  {_q('pass:' + name)} -> {_q('res:' + r)} [label=\"create\"{style}];")
        for r in b.writes:
            if r not in b.creates:
                out.append(f"  {_q('pass:' + name)} -> {_q('res:' + r)} [label=\"write\"{style}];")
        for r in b.reads:
            out.append(f"  {_q('res:' + r)} -> {_q('pass:' + name)} [label=\"read\"{style}];")
    out.append("}")
    return "\n".join(out) + "\n"
