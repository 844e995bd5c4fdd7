"""A picture of one compiled frame (``atmos graph NAME --png PATH``): passes in execution order down
the left, grouped by phase; the resources across the top; in each row what that pass does to each
resource (creates, writes, reads, with the version) and a bar over each texture's lifetime; culled
passes greyed at the bottom with the reason."""
from __future__ import annotations

from PIL import Image, ImageDraw, ImageFont

ROW, COL, PAD = 24, 62, 14                    # pixels: a pass row, a resource column, the margins
INK, GREY, FAINT, BAND = (30, 34, 40), (135, 140, 150), (225, 228, 233), (244, 246, 249)
CREATE, WRITE, READ = (46, 160, 90), (225, 120, 40), (50, 110, 210)
LIFE, IMPORTED = (200, 214, 235), (222, 206, 240)


def _font(size: int):
    try:
        return ImageFont.load_default(size=size)
    except TypeError:                         # Pillow < 10.1: the fixed bitmap font
        return ImageFont.load_default()


def _rotated(text: str, font, fill) -> Image.Image:
    """``text`` turned 45° up (a column heading)."""
    box = font.getbbox(text)
    label = Image.new("RGBA", (box[2] + 4, box[3] + 4), (0, 0, 0, 0))
    ImageDraw.Draw(label).text((2, 0), text, font=font, fill=fill)
    return label.rotate(45, expand=True, resample=Image.BICUBIC)


def draw_frame(compiled, title: str = "") -> Image.Image:
    """The picture of a :class:`~atmos.graph.compiler.CompiledGraph` (module docstring) as an RGB image."""
    font, small, bold = _font(13), _font(10), _font(15)
    kept = compiled.kept
    names = [n for n, info in compiled.resources.items() if info.lifetime is not None]
    rows: list[tuple[str, str | None]] = []   # ("phase", name) headings and ("pass", name) rows
    phase = None
    for name in kept:
        if compiled.phases[name] != phase:
            phase = compiled.phases[name]
            rows.append(("phase", phase))
        rows.append(("pass", name))
    label_w = PAD + max((font.getbbox(f"{i:2d}. {n}")[2] for i, n in enumerate(kept, 1)), default=100) + 24
    head = 56 + max((_rotated(n, font, INK).height for n in names), default=0)
    culled = list(compiled.culled.items())
    overhang = max((_rotated(n, font, INK).width for n in names[-3:]), default=0)
    width = max(label_w + COL * len(names) + overhang, 520)
    height = head + ROW * len(rows) + PAD + (ROW * (len(culled) + 1) if culled else 0) + 28
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    draw.text((PAD, PAD), title or "one frame", font=bold, fill=INK)
    x = PAD
    for colour, word, hollow in ((CREATE, "creates", False), (WRITE, "writes", False), (READ, "reads", True),
                                 (IMPORTED, "imported", False), (LIFE, "alive (pooled texture)", False)):
        x += 220 if x == PAD else 0
        draw.ellipse((x, PAD + 3, x + 10, PAD + 13), outline=colour, fill=None if hollow else colour, width=2)
        draw.text((x + 14, PAD), word, font=font, fill=INK)
        x += 14 + font.getbbox(word)[2] + 18
    centre = {n: label_w + COL * i + COL // 2 for i, n in enumerate(names)}
    for n in names:
        label = _rotated(n, font, INK if not compiled.resources[n].imported else (110, 70, 160))
        image.paste(label, (centre[n] - 6, head - label.height - 4), label)
    row_of = {name: i for i, (kind, name) in enumerate(rows) if kind == "pass"}
    index_row = {i: row_of[name] for i, name in enumerate(kept)}
    y0 = head
    for i, (kind, name) in enumerate(rows):
        y = y0 + ROW * i
        if kind == "phase":
            draw.rectangle((PAD, y + 2, width - PAD, y + ROW - 2), fill=BAND)
            draw.text((PAD + 4, y + 5), f"[{name}]", font=font, fill=GREY)
    for n in names:                           # lifetimes under the marks
        info = compiled.resources[n]
        first, last = info.lifetime
        top, bottom = y0 + ROW * index_row[first] + 4, y0 + ROW * index_row[last] + ROW - 4
        draw.rounded_rectangle((centre[n] - 5, top, centre[n] + 5, bottom), radius=5,
                               fill=IMPORTED if info.imported else LIFE)
    for i, name in enumerate(kept, start=1):
        y = y0 + ROW * row_of[name]
        draw.text((PAD + 10, y + 5), f"{i:2d}. {name}", font=font, fill=INK)
        builder = compiled.declarations[name]
        reads, writes = compiled.reads[name], compiled.writes[name]
        for r in centre:
            if r not in reads and r not in writes:
                continue
            cx, cy = centre[r], y + ROW // 2
            if r in writes:                   # a blend reads and writes: "@3>4", ringed in the read colour
                colour = CREATE if r in builder.creates else WRITE
                draw.ellipse((cx - 6, cy - 6, cx + 6, cy + 6), outline=READ if r in reads else colour, fill=colour,
                             width=2)
                text = f"@{reads[r]}>{writes[r]}" if r in reads else f"@{writes[r]}"
            else:
                colour = READ
                draw.ellipse((cx - 6, cy - 6, cx + 6, cy + 6), outline=colour, fill="white", width=2)
                text = f"@{reads[r]}"
            draw.text((cx + 8, cy - 6), text, font=small, fill=colour)
    y = y0 + ROW * len(rows) + PAD
    if culled:
        draw.text((PAD, y), "culled (allocate nothing):", font=font, fill=GREY)
        for k, (name, reason) in enumerate(culled, start=1):
            draw.text((PAD + 10, y + ROW * k), f"{name}  [{compiled.phases[name]}]  {reason}", font=font, fill=GREY)
    return image
