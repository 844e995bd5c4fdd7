"""Sound: a WAV checked when made; headless, Audio.play records what a game would have played (frame,
name, volume) and needs no audio device; bad sounds and volumes are named."""
import math
import struct
import wave

import pytest

from atmos import App, Audio, Sound, SoundPlugin


def beep(path, seconds=0.1, rate=22050):
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1), w.setsampwidth(2), w.setframerate(rate)
        w.writeframes(b"".join(struct.pack("<h", int(8000 * math.sin(2 * math.pi * 440 * i / rate)))
                               for i in range(int(seconds * rate))))
    return path


def test_a_headless_game_records_what_it_plays(tmp_path):
    boom = Sound(beep(tmp_path / "boom.wav", 0.25))
    assert boom.name == "boom" and boom.duration == pytest.approx(0.25, abs=1 / 22050) and boom.channels == 1
    app = App().add_plugins(SoundPlugin())
    audio = app.resource(Audio)
    assert not audio.audible
    app.add_system(lambda app: app.clock.frame == 3 and app.resource(Audio).play(boom, volume=0.5))
    app.run_frames(5)
    assert audio.played == [(3, "boom", 0.5)]


def test_bad_sounds_and_volumes_are_named(tmp_path):
    with pytest.raises(ValueError, match="Sound: no such file"):
        Sound(tmp_path / "none.wav")
    (tmp_path / "text.wav").write_text("not a wave")
    with pytest.raises(ValueError, match="is not a PCM WAV file"):
        Sound(tmp_path / "text.wav")
    app = App().add_plugins(SoundPlugin())
    with pytest.raises(ValueError, match="Audio.play.volume must be a finite number >= 0.0 and <= 1.0"):
        app.resource(Audio).play(Sound(beep(tmp_path / "b.wav")), volume=2.0)
    with pytest.raises(ValueError, match="Audio.play takes a Sound"):
        app.resource(Audio).play("b.wav")
    assert app.resource(Audio).played == []


@pytest.mark.skipif(__import__("shutil").which("Xvfb") is None, reason="Xvfb is not installed (setup.sh installs it)")
def test_in_a_window_the_sound_goes_out_through_pyglet(display, tmp_path):
    """A window's App plays through pyglet's media (a silent driver where the machine has no audio)."""
    import os
    import subprocess
    import sys
    path = beep(tmp_path / "ding.wav")
    script = f"""
import pyglet
from atmos import Audio, Sound, SoundPlugin, run
played = []
def build(app, settings):
    app.add_plugins(SoundPlugin())
    sound = Sound({str(path)!r})
    def once(app):
        if app.clock.frame == 2:
            played.append((app.resource(Audio).audible, app.resource(Audio).play(sound, 0.7)))
    app.add_system(once)
run(build, size=(64, 48), frames=5, headless=False)
audible, player = played[0]
print(audible, type(player).__name__, round(player.volume, 2))
"""
    done = subprocess.run([sys.executable, "-c", script], env=dict(os.environ, DISPLAY=display), capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[-3:] == ["True", "Player", "0.7"], done.stdout
