"""Sound for games: ``Sound("boom.wav")`` checked when made, played with
``app.resource(Audio).play(boom, volume=0.8)`` once :class:`SoundPlugin` is added.

In a window the sound goes out through pyglet's media (its own driver choice: PulseAudio, OpenAL,
DirectSound, or silence where there is none); headless (tests, renders into files) nothing is
played and nothing is needed: each call is recorded in :attr:`Audio.played` as (frame, name, volume),
so a test or a scripted run can check what a game would have played.
"""
from __future__ import annotations

import wave
from pathlib import Path

from atmos.checks import check_num
from atmos.plugin import Plugin


class Sound:
    """A WAV file (PCM, any rate and channels), checked and read now: a ValueError names the file and why."""

    def __init__(self, path):
        self.path = Path(path)
        try:
            with wave.open(str(self.path), "rb") as w:
                self.channels, self.rate, frames = w.getnchannels(), w.getframerate(), w.getnframes()
        except FileNotFoundError:
            raise ValueError(f"Sound: no such file {self.path}") from None
        except (wave.Error, EOFError, OSError) as error:
            raise ValueError(f"Sound: {self.path} is not a PCM WAV file ({error})") from None
        self.duration = frames / self.rate if self.rate else 0.0
        self.name = self.path.stem
        self._source = None                          # pyglet's decoded copy, made on first play in a window


class Audio:
    """The App's audio (a resource of :class:`SoundPlugin`): :meth:`play`, and :attr:`played`."""

    def __init__(self, app, audible: bool):
        self._app = app
        self.audible = audible                       # a window's context: played through pyglet
        self.played: list[tuple[int, str, float]] = []

    def play(self, sound: Sound, volume: float = 1.0):
        """Play ``sound`` at ``volume`` (0..1) now; returns pyglet's player in a window, else None."""
        if not isinstance(sound, Sound):
            raise ValueError(f"Audio.play takes a Sound (Sound('file.wav')), got {type(sound).__name__}")
        volume = check_num("Audio.play", "volume", volume, 0.0, 1.0)
        self.played.append((self._app.clock.frame, sound.name, volume))
        if not self.audible:
            return None
        import pyglet.media                          # needs the window's display: imported only here
        if sound._source is None:
            sound._source = pyglet.media.load(str(sound.path), streaming=False)
        player = sound._source.play()
        player.volume = volume
        return player


class SoundPlugin(Plugin):
    """Inserts the App's :class:`Audio`: audible in a window, recorded only when headless."""

    def build(self, app) -> None:
        audible = app.gpu is not None and not app.gpu.headless
        app.insert_resource(Audio(app, audible))
