"""Writing rendered frames to PNG, GIF, MP4 or a folder of PNGs, as a render-graph side effect."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.plugin import Plugin
from atmos.render_core import SCREEN

VIDEO = "video"
SUFFIXES = (".png", ".gif", ".mp4")


def output_kind(path: str | Path) -> str:
    """'png', 'gif', 'mp4' or 'dir' for an --out path; a ValueError names what is allowed."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in SUFFIXES:
        return suffix[1:]
    if suffix == "" or path.is_dir():
        return "dir"
    raise ValueError(f"--out {path}: unsupported file type {suffix!r}; use FILE.mp4, FILE.gif, FILE.png "
                     "(the last frame) or a folder (one PNG per frame)")


class FrameWriter:
    """Collects frames (uint8 RGB, top row first) into the file ``path`` names."""

    def __init__(self, path: str | Path, fps: float = 30.0):
        self.path = Path(path)
        self.kind = output_kind(self.path)
        self.fps = fps
        self.frames_written = 0
        self._last: np.ndarray | None = None
        self._writer = None
        target = self.path if self.kind == "dir" else self.path.parent
        target.mkdir(parents=True, exist_ok=True)

    def write(self, frame: np.ndarray) -> None:
        import imageio.v2 as imageio
        if self.kind == "dir":
            imageio.imwrite(self.path / f"frame_{self.frames_written:05d}.png", frame)
        elif self.kind == "png":
            self._last = frame
        else:
            if self._writer is None:
                if self.kind == "gif":
                    self._writer = imageio.get_writer(self.path, mode="I", duration=1000.0 / self.fps, loop=0)
                else:
                    self._writer = imageio.get_writer(self.path, fps=self.fps, codec="libx264", quality=8,
                                                      macro_block_size=2, ffmpeg_log_level="error")
            self._writer.append_data(frame)
        self.frames_written += 1

    def close(self) -> None:
        import imageio.v2 as imageio
        if self.kind == "png" and self._last is not None:
            imageio.imwrite(self.path, self._last)
        if self._writer is not None:
            self._writer.close()
            self._writer = None


class EncodePass(RenderPass):
    """Reads the finished screen image back and hands it to the writer (a side effect)."""
    name = "encode"
    phase = "readback"

    def __init__(self, writer: FrameWriter):
        self.writer = writer

    def setup(self, builder: PassBuilder) -> None:
        builder.read(SCREEN)
        builder.write(VIDEO)

    def execute(self, frame: PassContext) -> None:
        self.writer.write(frame.gpu.read_pixels())


class OutputPlugin(Plugin):
    """Records every rendered frame to ``path`` (see :func:`output_kind`)."""

    def __init__(self, path: str | Path, fps: float = 30.0):
        self.writer = FrameWriter(path, fps)

    def build(self, app) -> None:
        app.graph.import_resource(VIDEO, self.writer)
        app.graph.add_pass(EncodePass(self.writer))

    def cleanup(self, app) -> None:
        self.writer.close()
