"""Writing rendered frames to PNG, GIF, MP4 or a folder of PNGs, as a render-graph side effect.

Never half-written: the path is checked when the writer is made, before anything renders (its folder
made, a probe file created there); frames go to a temporary file beside the target (``.NAME.*.partial.EXT``)
that is renamed onto it only once complete; a failure (full disk, read-only folder, ffmpeg exiting
with an error) deletes what this writer wrote and raises :class:`OutputError`.
"""
from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

import numpy as np

from atmos.checks import check_num

from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.plugin import Plugin
from atmos.render_core import SCREEN

VIDEO = "video"
SUFFIXES = (".png", ".gif", ".mp4")


class OutputError(RuntimeError):
    """An output file cannot be written (or its writing failed); the message names the file and why.
    Nothing half-written is left behind."""


def output_kind(path: str | Path) -> str:
    """'png', 'gif', 'mp4' or 'dir' for an --out path; a ValueError names what is allowed."""
    text = os.fspath(path) if isinstance(path, (str, Path)) else None
    if not text:
        raise ValueError(f"--out {path!r}: give FILE.mp4, FILE.gif, FILE.png (the last frame) or a folder "
                         "(one PNG per frame), not an empty name")
    path = Path(text)
    suffix = path.suffix.lower()
    if suffix in SUFFIXES and text.endswith(("/", os.sep)):
        raise ValueError(f"--out {text}: ends with '/' (a folder) but names a {suffix} file; "
                         f"drop the '/' for the file, or name the folder without {suffix}")
    if suffix in SUFFIXES:
        return suffix[1:]
    if suffix == "" or path.is_dir():
        return "dir"
    raise ValueError(f"--out {path}: unsupported file type {suffix!r}; use FILE.mp4, FILE.gif, FILE.png "
                     "(the last frame) or a folder (one PNG per frame)")


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _reason(error: OSError) -> str:
    where = error.filename if error.filename is not None else ""
    return f"{error.strerror or error}" + (f" ({where})" if where else "")


def check_output(path: str | Path) -> tuple[Path, str]:
    """``(path, kind)`` once ``path`` is known to be writable: its folder made, a probe file created and
    removed in it. :class:`OutputError` names the path and why not (a ValueError for a bad name)."""
    kind = output_kind(path)
    path = Path(path)
    folder = path if kind == "dir" else path.parent
    if kind == "dir" and path.exists() and not path.is_dir():
        raise OutputError(f"cannot write frames into {path}: it is a file, not a folder; give a folder, "
                          "or FILE.mp4, FILE.gif or FILE.png")
    existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
    if existing is not None and not existing.is_dir():
        raise OutputError(f"cannot write {path}: {existing} is a file, not a folder")
    if kind != "dir" and path.is_dir():
        raise OutputError(f"cannot write {path}: it is a folder; give a file name, or a folder name "
                          f"without {path.suffix} for one PNG per frame")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"cannot write {path}: {_reason(error)}") from None
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".atmos-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as error:
        raise OutputError(f"cannot write {path}: {error.strerror or error} (in {folder})") from None
    return path, kind


def check_shots(shots, frames: int | None = None) -> tuple[int, ...] | None:
    """``shots`` (frame numbers, from 0, or text such as "30,150,215") as sorted unique ints; each below
    ``frames`` when given. None passes."""
    if shots is None:
        return None
    items = shots.split(",") if isinstance(shots, str) else shots
    try:
        values = sorted({int(str(s).strip()) for s in items})
    except (TypeError, ValueError):
        raise ValueError(f"shots must be frame numbers such as 30,150,215; got {shots!r}") from None
    if not values or values[0] < 0:
        raise ValueError(f"shots must be frame numbers >= 0 (the first frame is 0); got {shots!r}")
    if frames is not None and values[-1] >= frames:
        raise ValueError(f"shot {values[-1]} is past the last frame ({frames} frames: 0..{frames - 1})")
    return tuple(values)


class FrameWriter:
    """Collects frames (uint8 RGB, top row first) into the file ``path`` names, never half-written
    (the module docstring): :meth:`close` completes the file, :meth:`abort` gives up and deletes what
    was written. After either, writing is an OutputError. ``shots`` (a folder only): the frame numbers
    to keep, each written as ``frame_NNNNN.png`` by its number; the others are skipped unread."""

    def __init__(self, path: str | Path, fps: float = 30.0, shots=None):
        kind = output_kind(path)
        self.shots = check_shots(shots)
        if self.shots is not None and kind != "dir":
            raise OutputError(f"{path}: shots are written one PNG each, so the output must be a folder (end it "
                              f"with a slash: frames/), not a .{kind} file")
        folder = Path(path) if kind == "dir" else Path(path).parent
        self._new_folders = [f for f in (folder, *folder.parents) if not f.exists()]   # deepest first
        self.path, self.kind = check_output(path)
        self.fps = check_num("FrameWriter", "fps", fps, 0.0, 1000.0, lo_open=True)
        self.frame_index = 0                      # frames offered so far (written or skipped)
        self.frames_written = 0
        self.state = "open"                       # then "done" (close) or "failed" (abort, an error)
        self._last: np.ndarray | None = None
        self._encoder = None
        self._temp: Path | None = None
        self._made: list[Path] = []               # a folder's PNGs written by this writer

    def wants(self) -> bool:
        """Whether the next frame is written (every frame, or the next one is a shot)."""
        return self.shots is None or self.frame_index in self.shots

    def skip(self) -> None:
        """The next frame is not a shot: count it without reading it."""
        self.frame_index += 1

    def write(self, frame: np.ndarray) -> None:
        if self.state != "open":
            raise OutputError(f"{self.path}: this writer is {self.state}; make a new FrameWriter")
        if not self.wants():
            self.skip()
            return
        try:
            if self.kind == "dir":
                name = self.path / f"frame_{self.frame_index:05d}.png"
                self._complete(self._write_png(frame), name)
                self._made.append(name)
            elif self.kind == "png":
                self._last = np.array(frame, copy=True)
            else:
                if self._encoder is None:
                    self._encoder = self._open_encoder()
                self._encoder.write(frame)
        except Exception as error:
            self._fail(error)
        self.frames_written += 1
        self.frame_index += 1

    def close(self) -> None:
        """Complete the file (rename it into place); OutputError if that fails. Again: nothing."""
        if self.state != "open":
            return
        try:
            if self.kind == "png" and self._last is not None:
                self._complete(self._write_png(self._last), self.path)
            elif self._encoder is not None:
                self._encoder.close()
                self._encoder = None
                self._complete(self._temp, self.path)
        except Exception as error:
            self._fail(error)
        self.state = "done"

    def abort(self) -> None:
        """Give up: stop the encoder, delete the temporary file and the PNGs this writer made."""
        if self.state != "open":
            return
        self.state = "failed"
        if self._encoder is not None:
            try:
                self._encoder.abort()
            except Exception:                    # the file is deleted anyway
                pass
            self._encoder = None
        for path in [self._temp, *self._made]:
            if path is not None:
                try:
                    path.unlink(missing_ok=True)
                except OSError:
                    pass
        self._temp = None
        self._made.clear()
        for folder in self._new_folders:          # the folders check_output made for this writer, if empty
            try:
                folder.rmdir()
            except OSError:
                break

    # -- internals ---------------------------------------------------------------------------
    def _fail(self, error: Exception):
        self.abort()
        reason = _reason(error) if isinstance(error, OSError) else f"{type(error).__name__}: {error}"
        raise OutputError(f"writing {self.path} failed after {self.frames_written} frame(s): {reason}; "
                          "nothing was left behind") from error

    def _temporary(self) -> Path:
        """A new empty temporary file beside the target, ending in the target's suffix."""
        folder = self.path if self.kind == "dir" else self.path.parent
        fd, name = tempfile.mkstemp(dir=folder, prefix=f".{self.path.name}.", suffix=f".partial.{self._suffix}")
        os.close(fd)
        os.chmod(name, 0o666 & ~_umask())          # mkstemp makes it private; the result is an ordinary file
        self._temp = Path(name)
        return self._temp

    @property
    def _suffix(self) -> str:
        return "png" if self.kind in ("dir", "png") else self.kind

    def _write_png(self, frame: np.ndarray) -> Path:
        """The PNG encoded in memory, then written and closed here: a full disk is one OSError now (an
        image library's writer left open would raise again when collected, as a stray traceback)."""
        from PIL import Image
        buffer = io.BytesIO()
        Image.fromarray(np.ascontiguousarray(frame, np.uint8)).save(buffer, format="PNG")
        temp = self._temporary()
        with open(temp, "wb") as file:
            file.write(buffer.getbuffer())
        return temp

    def _complete(self, temp: Path, target: Path) -> None:
        os.replace(temp, target)
        self._temp = None

    def _open_encoder(self):
        from atmos.video import GifEncoder, Mp4Encoder
        return (GifEncoder if self.kind == "gif" else Mp4Encoder)(self._temporary(), self.fps)


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
        if self.writer.wants():
            self.writer.write(frame.gpu.read_pixels())
        else:
            self.writer.skip()                    # not a shot: no read-back


class OutputPlugin(Plugin):
    """Records every rendered frame (or the ``shots``: :class:`FrameWriter`) to ``path`` (see
    :func:`output_kind`), checked now (before anything renders); ``App.close`` completes the file (a run
    that failed calls ``plugin.writer.abort()`` first)."""

    def __init__(self, path: str | Path, fps: float = 30.0, shots=None):
        super().__init__()
        self.writer = FrameWriter(path, fps, shots)

    def build(self, app) -> None:
        app.graph.import_resource(VIDEO, self.writer)
        app.graph.add_pass(EncodePass(self.writer))

    def cleanup(self, app) -> None:
        self.writer.close()
