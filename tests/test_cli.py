"""The atmos command: demos render headless and are not blank; bad arguments get clear messages."""
import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from atmos.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_demo_list(capsys):
    code, out, _ = run(capsys, "demo", "--list")
    assert code == 0 and "testbed" in out


def test_info(capsys):
    code, out, _ = run(capsys, "info")
    assert code == 0 and "GL_RENDERER" in out and "GL_VERSION" in out
    from atmos.gpu import create_headless
    gpu = create_headless((8, 8))
    software = gpu.software
    gpu.release()
    line = next(l for l in out.splitlines() if l.startswith("software rasterizer"))
    assert line.split()[2] == ("yes:" if software else "no"), line


def test_info_into_a_closed_pipe_is_not_an_error():
    """`atmos info | head -3` under pipefail (setup.sh did this): a reader that stops early is fine."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    done = subprocess.run([sys.executable, "-c", "import sys; from atmos.cli import main; sys.exit(main(['info']))"],
                          stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    os.close(write_end)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr


def test_graph_text_and_dot(capsys):
    code, out, _ = run(capsys, "graph", "testbed")
    assert code == 0 and "present" in out and "template_volume" in out
    code, out, _ = run(capsys, "graph", "testbed", "--dot")
    assert code == 0 and out.lstrip().startswith("digraph")


def test_graph_picture_draws_a_band_per_phase_and_the_marks(capsys, tmp_path):
    from atmos.graph.picture import BAND, CREATE, PAD, READ, WRITE
    path = tmp_path / "frame.png"
    code, out, _ = run(capsys, "graph", "sunset", "--png", str(path))
    assert code == 0 and f"wrote {path}" in out
    order = out.split("culled:")[0]
    phases = [line.strip() for line in order.splitlines() if line.startswith("  [")]
    image = np.asarray(Image.open(path).convert("RGB"))
    edge = np.all(image[:, PAD + 2] == BAND, axis=-1)           # the phase headings' bands, top to bottom
    assert int(np.count_nonzero(edge[1:] & ~edge[:-1])) == len(phases) == 7   # media: the fog is in the shafts' apply
    colours = {tuple(c) for c in image.reshape(-1, 3)}
    assert {CREATE, WRITE, READ} <= colours


def test_graph_of_the_cloud_demo_runs_no_simulation(capsys, monkeypatch):
    from atmos.slicing import SlicedJob

    def refuse(*args, **kwargs):
        raise AssertionError("atmos graph ran a simulation slice")
    monkeypatch.setattr(SlicedJob, "_run_one", refuse)
    code, out, _ = run(capsys, "graph", "sunset")
    assert code == 0
    for phase in ("[sky]", "[opaque]", "[shadows]", "[translucent]", "[post]", "[present]"):
        assert phase in out
    assert "cloud_sets@0" in out and "(plugins/clouds/raymarch/plugin.py:" in out
    kept, culled = out.split("culled:")[0], out.split("culled:")[1].split("resources:")[0]
    assert ". cloud_raymarch " in kept and "- cloud_render " in culled, "the ray march by default, the sprites off"


def test_graph_of_the_cloud_demo_with_the_sprites(capsys):
    code, out, _ = run(capsys, "graph", "sunset", "--clouds", "sprites")
    assert code == 0
    kept, culled = out.split("culled:")[0], out.split("culled:")[1].split("resources:")[0]
    assert ". cloud_render " in kept and "(plugins/clouds/sprites/plugin.py:" in kept
    assert ". cloud_raymarch " in kept and "- cloud_far_field " in culled, "the march draws the far field alone"


def test_graph_of_the_hazy_demo_with_the_air(capsys):
    code, out, _ = run(capsys, "graph", "sunset", "--haze", "air")
    assert code == 0
    kept, culled = out.split("culled:")[0], out.split("culled:")[1].split("resources:")[0]
    assert ". fog " not in kept and "- aerial_perspective " in culled, \
        "the air instead of the haze fog, composited by the light shafts' froxel apply"
    assert "aerial_volume" in kept.split(". light_shafts ")[1].splitlines()[0], "the shafts fill the air's froxels"


def test_headless_demo_frames_are_not_blank_and_move(tmp_path, capsys):
    code, out, _ = run(capsys, "demo", "testbed", "--headless", "--frames", "24", "--size", "160x90",
                       "--out", str(tmp_path), "--quiet")
    assert code == 0 and "wrote 24 frames" in out
    frames = [np.asarray(Image.open(tmp_path / f"frame_{i:05d}.png"), float) for i in (0, 23)]
    for img in frames:
        assert img.shape == (90, 160, 3)
        assert img.std() > 10, "a blank frame"
        sky, ground = img[:10].mean(axis=(0, 1)), img[-10:].mean(axis=(0, 1))
        assert sky[2] > sky[0], "the sky is bluish at the top"
        assert np.abs(sky - ground).sum() > 30, "sky and ground differ"
    assert np.abs(frames[0] - frames[1]).mean() > 0.5, "the scene animates"


@pytest.mark.parametrize("suffix", ["gif", "mp4", "png"])
def test_headless_demo_writes_files(tmp_path, capsys, suffix):
    path = tmp_path / f"demo.{suffix}"
    code, out, _ = run(capsys, "demo", "testbed", "--headless", "--frames", "3", "--size", "64x36",
                       "--out", str(path), "--quiet")
    assert code == 0 and path.stat().st_size > 100


@pytest.mark.parametrize("argv, message", [
    (["demo", "nosuch", "--headless"], "unknown demo 'nosuch'; available: "),
    (["demo", "--size", "big"], "'big' is not WxH"),
    (["demo", "--size", "0x10"], "between 1 and 16384"),
    (["demo", "--size", "-5x10"], "argument --size: '-5x10': width and height must be between 1 and 16384"),
    (["demo", "--frames", "-2"], "argument --frames: -2 is not allowed; give 1 or more"),
    (["demo", "--frames", "0"], "0 is not allowed; give 1 or more"),
    (["demo", "--frames", "many"], "'many' is not a whole number"),
    (["demo", "--seed", "-3"], "seeds are 0 .. 4294967295"),
    (["demo", "--out", "movie.avi"], "unsupported file type '.avi'"),
    (["graph", "nosuch"], "unknown demo 'nosuch'"),
    (["demo", "--clouds", "voxels"], "argument --clouds: invalid choice: 'voxels' (choose from"),
    (["run", "demos/glider.py", "--clouds", "cubes"], "invalid choice: 'cubes'"),
    (["graph", "sunset", "--clouds", "both"], "argument --clouds: invalid choice: 'both' (choose from"),
    (["demo", "--haze", "smoke"], "argument --haze: invalid choice: 'smoke' (choose from"),
    (["graph", "sunset", "--sky", "preetham", "--haze", "air"], "--haze air is the physical sky's aerial perspective"),
])
def test_bad_arguments_get_clear_messages(capsys, argv, message):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    assert message in capsys.readouterr().err
