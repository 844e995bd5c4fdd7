"""Animation encoders with one interface (``write(frame)``, ``close()``, ``abort()``): MP4 (H.264)
through an ffmpeg subprocess fed raw RGB frames on its stdin, and GIF through Pillow.

ffmpeg is imageio-ffmpeg's binary. Unlike imageio's writer, a failure is never silent: a frame ffmpeg
cannot take and an ffmpeg that exits non-zero (a full disk: "No space left on device") raise OSError
with ffmpeg's own message. Frames of odd width or height are padded by one black pixel row or column
(H.264 in yuv420p needs even sizes), not resampled.
"""
from __future__ import annotations

import subprocess
import tempfile
from fractions import Fraction
from pathlib import Path

import numpy as np

CRF = 10        # x264 constant rate factor: 0 lossless .. 51 worst (imageio's quality=8)


class Mp4Encoder:
    """Frames (uint8 RGB, (h, w, 3), one size) → an MP4 at ``path``; :meth:`close` waits for ffmpeg
    and raises OSError if it failed; :meth:`abort` stops it (the file is then incomplete)."""

    def __init__(self, path: str | Path, fps: float = 30.0):
        self.path = Path(path)
        self.fps = fps
        self.size: tuple[int, int] | None = None
        self._proc: subprocess.Popen | None = None
        self._log = None

    def _start(self, width: int, height: int) -> None:
        try:
            import imageio_ffmpeg
            exe = imageio_ffmpeg.get_ffmpeg_exe()
        except (ImportError, RuntimeError) as error:
            raise OSError(f"MP4 output needs the ffmpeg of imageio-ffmpeg (pip install imageio-ffmpeg): {error}") from None
        fps = Fraction(self.fps).limit_denominator(1001)
        cmd = [exe, "-y", "-nostdin", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{width}x{height}", "-r", str(fps), "-i", "-", "-an",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-vcodec", "libx264", "-pix_fmt", "yuv420p",
               "-crf", str(CRF), "-f", "mp4", str(self.path)]
        self._log = tempfile.TemporaryFile()
        self._proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=self._log)
        self.size = (width, height)

    def write(self, frame: np.ndarray) -> None:
        frame = np.ascontiguousarray(frame, dtype=np.uint8)
        if frame.ndim != 3 or frame.shape[2] != 3:
            raise ValueError(f"MP4 frames must be uint8 RGB of shape (height, width, 3), got {frame.shape}")
        height, width = frame.shape[:2]
        if self._proc is None:
            self._start(width, height)
        elif (width, height) != self.size:
            raise ValueError(f"an MP4 keeps one frame size: this frame is {width}x{height}, the first was "
                             f"{self.size[0]}x{self.size[1]}")
        try:
            self._proc.stdin.write(frame.data)
        except OSError:                     # ffmpeg stopped (BrokenPipeError): it says why on exit
            self._finish()
            raise OSError(f"ffmpeg stopped while encoding {self.path}: {self._message()}") from None

    def close(self) -> None:
        """Wait for ffmpeg to finish the file; OSError with its message if it failed."""
        if self._proc is None:
            return
        code = self._finish()
        if code != 0:
            raise OSError(f"ffmpeg failed (exit status {code}) writing {self.path}: {self._message()}")

    def abort(self) -> None:
        """Stop ffmpeg without waiting for the file."""
        if self._proc is not None and self._proc.poll() is None:
            self._proc.kill()
        if self._proc is not None:
            self._finish()

    def _finish(self) -> int:
        proc = self._proc
        try:
            proc.stdin.close()
        except OSError:
            pass
        return proc.wait()

    def _message(self) -> str:
        self._log.seek(0)
        text = self._log.read().decode(errors="replace").strip().splitlines()
        return " / ".join(text[-3:]) or "no message"


class GifEncoder:
    """Frames (uint8 RGB) → a looping GIF at ``path`` (Pillow; an adaptive palette per frame), written
    by :meth:`close` (OSError when that fails); :meth:`abort` drops the frames."""

    def __init__(self, path: str | Path, fps: float = 30.0):
        self.path = Path(path)
        self.fps = fps
        self._frames: list = []

    def write(self, frame: np.ndarray) -> None:
        from PIL import Image
        self._frames.append(Image.fromarray(np.ascontiguousarray(frame, dtype=np.uint8)))   # (h, w, 3) uint8: RGB

    def close(self) -> None:
        frames, self._frames = self._frames, []
        if frames:
            with open(self.path, "wb") as file:
                frames[0].save(file, format="GIF", save_all=True, append_images=frames[1:],
                               duration=1000.0 / self.fps, loop=0)

    def abort(self) -> None:
        self._frames = []
