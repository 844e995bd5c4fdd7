"""Output is never half-written: the path is checked before rendering, frames go to a temporary file
renamed when complete, a full disk or a failing encoder is an OutputError (a non-zero exit from the
command) and leaves nothing behind."""
import os
import resource
import subprocess
import sys
from contextlib import contextmanager

import numpy as np
import pytest

from atmos.cli import main
from atmos.output import FrameWriter, OutputError, OutputPlugin, _umask
from atmos.runner import run_headless
from atmos.demo_registry import DemoSettings

KINDS = ["clip.mp4", "clip.gif", "still.png", "frames"]


def noise(rng, n=12, size=(160, 120)):
    """Frames that do not compress: a few of them fill any small disk."""
    return [rng.integers(0, 256, (size[1], size[0], 3), dtype=np.uint8) for _ in range(n)]


@contextmanager
def file_size_limit(limit: int):
    """Files (of this process and of ffmpeg, which inherits it) cannot grow past ``limit`` bytes: a
    disk that fills up, without root. Python ignores SIGXFSZ (a write fails with EFBIG); ffmpeg is
    stopped by it."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))


def left_in(folder):
    return sorted(p.name for p in folder.rglob("*"))


@pytest.mark.parametrize("name", KINDS)
def test_a_full_disk_is_an_error_and_leaves_nothing(tmp_path, rng, name):
    writer = FrameWriter(tmp_path / name)
    with pytest.raises(OutputError, match=rf"writing .*{name} failed after \d+ frame\(s\): .*; nothing was left behind"):
        with file_size_limit(20_000):
            for frame in noise(rng):
                writer.write(frame)
            writer.close()
    assert writer.state == "failed"
    assert left_in(tmp_path) == [], "a truncated or temporary file (or the folder made for it) was left"


@pytest.mark.parametrize("name", KINDS)
def test_complete_files_appear_only_when_complete(tmp_path, rng, name):
    writer = FrameWriter(tmp_path / name, fps=24)
    frames = noise(rng, n=3, size=(33, 19))          # odd sizes: the MP4 is padded, not resampled
    for frame in frames:
        writer.write(frame)
        if name != "frames":
            assert not (tmp_path / name).exists(), "the target exists before it is complete"
    writer.close()
    target = tmp_path / name
    import imageio.v3 as iio
    if name == "frames":
        assert left_in(tmp_path) == sorted(["frames"] + [f"frame_{i:05d}.png" for i in range(3)])
        assert np.array_equal(iio.imread(target / "frame_00002.png"), frames[2])
    else:
        assert left_in(tmp_path) == [name], "only the finished file is left"
        assert target.stat().st_mode & 0o777 == 0o666 & ~_umask(), "an ordinary file, not a private temporary"
        data = iio.imread(target, index=None) if name != "still.png" else iio.imread(target)
        if name == "still.png":
            assert np.array_equal(data, frames[-1])
        else:
            assert data.shape[0] == 3 and data.shape[1:3] == ((20, 34) if name.endswith("mp4") else (19, 33))
    with pytest.raises(OutputError, match="this writer is done"):
        writer.write(frames[0])


def test_an_aborted_run_leaves_nothing_and_keeps_an_older_file(tmp_path, rng):
    old = tmp_path / "clip.mp4"
    old.write_bytes(b"an older video")
    writer = FrameWriter(old)
    for frame in noise(rng, n=2):
        writer.write(frame)
    writer.abort()
    assert left_in(tmp_path) == ["clip.mp4"] and old.read_bytes() == b"an older video"
    folder = FrameWriter(tmp_path / "new" / "deeper" / "frames")   # folders made for the writer go too
    folder.write(noise(rng, n=1)[0])
    folder.abort()
    assert left_in(tmp_path) == ["clip.mp4"]


@pytest.mark.parametrize("make, message", [
    (lambda tmp: tmp / "a_file" / "x.png", r"cannot write .*x\.png: .*a_file is a file, not a folder"),
    (lambda tmp: tmp / "a_file", r"cannot write frames into .*a_file: it is a file, not a folder"),
    (lambda tmp: tmp / "a_folder.mp4", r"cannot write .*a_folder\.mp4: it is a folder"),
    (lambda tmp: "", r"--out '': give FILE\.mp4, FILE\.gif, FILE\.png .* not an empty name"),
    (lambda tmp: f"{tmp}/x.gif/", r"ends with '/' \(a folder\) but names a \.gif file"),
    (lambda tmp: tmp / "x.avi", r"unsupported file type '\.avi'"),
])
def test_an_unwritable_path_is_refused_when_the_writer_is_made(tmp_path, make, message):
    (tmp_path / "a_file").write_text("not a folder")
    (tmp_path / "a_folder.mp4").mkdir()
    with pytest.raises((OutputError, ValueError), match=message):
        OutputPlugin(make(tmp_path))


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_refused_before_rendering(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with pytest.raises(OutputError, match=r"cannot write .*x\.png: Permission denied"):
            FrameWriter(folder / "x.png")
    finally:
        folder.chmod(0o755)


def test_a_run_that_fails_midway_leaves_no_file(tmp_path):
    failure = RuntimeError
    def build(app, settings):
        from atmos.defaults import DefaultPlugins
        from atmos.plugins.ground import GroundPlugin
        app.add_plugins(DefaultPlugins(overlay=False), GroundPlugin())

        def fail_late(app):
            if app.clock.frame > 3:
                raise failure("the game broke")
        app.add_system(fail_late, "update")

    with pytest.raises(failure, match="the game broke"):
        run_headless(build, DemoSettings(size=(32, 18), frames=8, headless=True), str(tmp_path / "x.mp4"),
                     progress=False)
    assert left_in(tmp_path) == []


@pytest.mark.parametrize("name", ["x.mp4", "x.gif", "frames", "still.png"])
def test_an_interrupted_run_keeps_a_valid_file_of_the_frames_so_far(tmp_path, capsys, name):
    """Ctrl-C (a script raises KeyboardInterrupt at frame 5) completes the output with the 5 frames
    rendered, as ffmpeg does; the command says so and exits 130."""
    import imageio.v3 as iio
    script = tmp_path / "stop.py"
    script.write_text("def step(app, frame):\n    if frame == 5:\n        raise KeyboardInterrupt\n")
    out = tmp_path / "out" / name
    code = main(["demo", "testbed", "--headless", "--frames", "20", "--size", "32x18", "--quiet", "--out", str(out),
                 "--script", str(script)])
    assert code == 130
    assert f"atmos: interrupted; wrote the 5 frame(s) rendered so far to {out}" in capsys.readouterr().err
    if name == "frames":
        assert left_in(out) == [f"frame_{i:05d}.png" for i in range(5)]
    elif name == "still.png":
        assert iio.imread(out).shape == (18, 32, 3)
    else:
        assert iio.imread(out, index=None).shape[0] == 5
    assert not [p for p in (tmp_path / "out").iterdir() if "partial" in p.name]
    stop_at_once = tmp_path / "stop0.py"
    stop_at_once.write_text("def step(app, frame):\n    raise KeyboardInterrupt\n")
    code = main(["demo", "testbed", "--headless", "--frames", "20", "--size", "32x18", "--quiet",
                 "--out", str(tmp_path / "none.mp4"), "--script", str(stop_at_once)])
    assert code == 130 and "before any frame was written; nothing was left behind" in capsys.readouterr().err
    assert not (tmp_path / "none.mp4").exists()


def test_the_command_checks_the_output_before_rendering_and_exits_1(tmp_path, capsys, monkeypatch):
    (tmp_path / "a_file").write_text("")
    from atmos.app import App
    monkeypatch.setattr(App, "update", lambda *a, **k: pytest.fail("rendered before the output was checked"))
    code = main(["demo", "testbed", "--headless", "--frames", "2", "--size", "32x18", "--quiet",
                 "--out", str(tmp_path / "a_file" / "x.png")])
    err = capsys.readouterr().err
    assert code == 1 and "atmos: cannot write" in err and "a_file is a file, not a folder" in err


def test_the_command_exits_non_zero_on_a_full_disk_and_says_why(tmp_path):
    """End to end, as a user sees it: the MP4 encoder fails at the end (ffmpeg killed by the file-size
    limit), the command exits 1 with one line, no traceback, no 'wrote N frames', no file."""
    out = tmp_path / "x.mp4"
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (8_000, resource.getrlimit(resource.RLIMIT_FSIZE)[1]))
    done = subprocess.run([sys.executable, "-m", "atmos", "demo", "testbed", "--headless", "--frames", "20",
                           "--size", "160x90", "--quiet", "--out", str(out)],
                          capture_output=True, text=True, timeout=300, preexec_fn=limit)
    assert done.returncode == 1, (done.stdout, done.stderr)
    assert "wrote" not in done.stdout and "Traceback" not in done.stderr
    assert f"atmos: writing {out} failed after" in done.stderr and "nothing was left behind" in done.stderr
    assert left_in(tmp_path) == []


@pytest.mark.parametrize("name", ["still.png", "frames"])
def test_a_full_disk_while_writing_pngs_leaves_no_writer_open(tmp_path, rng, monkeypatch, name):
    """The PNG goes to /dev/full (every write fails with ENOSPC, as on a full disk): one OutputError,
    and nothing raises again later when collected (an image writer left open did: a stray traceback)."""
    from pathlib import Path
    import gc

    def full_disk(writer):
        writer._temp = None                          # nothing of ours to delete
        return Path("/dev/full")
    monkeypatch.setattr(FrameWriter, "_temporary", full_disk)
    unraisable, hook = [], sys.unraisablehook
    sys.unraisablehook = unraisable.append
    try:
        writer = FrameWriter(tmp_path / name)
        with pytest.raises(OutputError, match="No space left on device; nothing was left behind"):
            for frame in noise(rng, n=2, size=(64, 48)):
                writer.write(frame)
            writer.close()
        del writer
        gc.collect()
    finally:
        sys.unraisablehook = hook
    assert unraisable == [], [str(u.exc_value) for u in unraisable]
