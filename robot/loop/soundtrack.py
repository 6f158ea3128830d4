"""A show's soundtrack and cues on the robot's computer: a tick observer of the loop that
starts an audio player when the show reaches the audio's start, and reports each cue as
the show passes it.

Playback is an external player, not a Python audio stack: ``aplay`` (ALSA's, on every
Raspberry Pi OS) or ``paplay`` (PulseAudio / PipeWire) fed the WAV on standard input, cut
here to the right start with the standard library's ``wave``; ``ffplay`` for any other
format (it seeks itself); or ``player``, a command that reads a WAV on standard input. The
player is started from a thread of its own, never the loop's, so a slow start of a process
costs the show no tick. No player, no audio device, a player that fails: one warning, and
the show runs silent.

Show time: 0 at the first tick of the source after the ramp in (the state "walking");
the audio's start plays at ``audio_offset_s`` of show time (robot/motion/show.py). A
chased show (``clock``) gives its own show time: a jump in it restarts the player at the
new place and the cues from there.
"""

from __future__ import annotations

import io
import logging
import shlex
import shutil
import subprocess
import threading
import wave
from collections.abc import Callable
from pathlib import Path

from robot.errors import ConfigError
from robot.loop.telemetry import Telemetry
from robot.motion.show import Cue, Show

log = logging.getLogger(__name__)

#: A chased show's time this far [s] from the loop's run: a jump; the player restarts.
SEEK_S = 0.25
#: Players fed a WAV on standard input, in the order tried.
STDIN_PLAYERS = (("aplay", "-q", "-"), ("paplay",))


def _unreadable(path: Path, e: Exception) -> ConfigError:
    why = (str(e) if str(e) else "it ends before its header is whole" if isinstance(
        e, EOFError) else type(e).__name__)
    return ConfigError(f"audio {path}: not a readable WAV file: {why}")


def check_wav(path: Path) -> None:
    """ConfigError naming ``path`` and why, unless its header reads as a PCM WAV file's
    (read before the show starts: a WAV that cannot play is refused, not a silent show)."""
    try:
        with wave.open(str(path), "rb") as w:
            w.getparams()
    except (OSError, EOFError, wave.Error) as e:
        raise _unreadable(path, e) from None


def wav_from(path: Path, skip_s: float) -> bytes:
    """The WAV file at ``path`` from ``skip_s`` [s] on, as a WAV (header and frames)."""
    try:
        with wave.open(str(path), "rb") as w:
            params = w.getparams()
            w.setpos(min(params.nframes, int(round(max(0.0, skip_s) * params.framerate))))
            frames = w.readframes(params.nframes)
    except (OSError, EOFError, wave.Error) as e:
        raise _unreadable(path, e) from None
    out = io.BytesIO()
    with wave.open(out, "wb") as w:
        w.setparams(params)
        w.writeframes(frames)
    return out.getvalue()


def player_command(path: Path, skip_s: float, player: str | None) -> tuple[list[str], bool]:
    """The command and whether it reads the WAV on stdin; ConfigError if none is found."""
    if player:
        return shlex.split(player), True
    if path.suffix.lower() == ".wav":
        for cmd in STDIN_PLAYERS:
            if shutil.which(cmd[0]):
                return list(cmd), True
    if shutil.which("ffplay"):
        return ["ffplay", "-nodisp", "-autoexit", "-loglevel", "error", "-ss",
                f"{max(0.0, skip_s):.3f}", str(path)], False
    raise ConfigError(f"audio {path}: no audio player found (aplay, paplay or ffplay; "
                      "or --player CMD)")


class Soundtrack:
    """``show``: its audio and cues; ``on_cue(cue)``: called (in the loop thread) as the
    show passes each cue; ``player``: a command reading a WAV on stdin (None: find one)."""

    def __init__(self, show: Show, *, on_cue: Callable[[Cue], None] | None = None,
                 player: str | None = None) -> None:
        self.show = show
        self.on_cue = on_cue
        self.player = player
        self.start: float | None = None          # loop time [s] of show time 0
        self.started_at: float | None = None     # show time [s] the player was started
        self._next_cue = 0
        self._done = threading.Event()
        self._proc: subprocess.Popen[bytes] | None = None
        self._thread: threading.Thread | None = None
        self.warning: str | None = None
        #: the show time [s] to follow instead of the loop's (a chased show), or None
        self.clock: Callable[[], float | None] | None = None
        self._last: tuple[float, float] | None = None
        path = show.audio_path()
        if path is not None and not path.is_file():
            raise ConfigError(f"audio {path}: file not found (relative to the file that "
                              "names it)")
        if path is not None and (player is not None or path.suffix.lower() == ".wav"):
            check_wav(path)             # fed to the player as a WAV: it must read as one

    def __call__(self, tel: Telemetry) -> None:
        if self.clock is not None:               # a chased show: its own show time
            chased = self.clock()
            if chased is None or tel.state != "walking":
                return
            t = self._follow(chased, tel.t)
        else:
            if self.start is None:
                if tel.state != "walking":
                    return
                self.start = tel.t
            t = tel.t - self.start
        cues = self.show.cues
        while self._next_cue < len(cues) and cues[self._next_cue].t <= t:
            if self.on_cue is not None:
                self.on_cue(cues[self._next_cue])
            self._next_cue += 1
        if self._thread is None and self.show.audio and t >= self.show.audio_offset_s:
            self.started_at = t
            self._thread = threading.Thread(target=self._play, args=(t,), daemon=True,
                                            name="soundtrack")
            self._thread.start()

    def _follow(self, t: float, loop_t: float) -> float:
        """Show time ``t`` [s] at loop time ``loop_t``; a jump (away from where the last
        tick's show time and the loop's time since put it by more than ``SEEK_S``) restarts
        the player there and puts the cues after ``t`` next."""
        last = self._last
        self._last = (t, loop_t)
        if last is not None and abs(t - (last[0] + loop_t - last[1])) > SEEK_S:
            old, self._proc, self._thread = self._proc, None, None   # the next tick starts one
            if old is not None:          # ended from a thread of its own, not the loop's
                threading.Thread(target=_end, args=(old,), daemon=True).start()
            self._next_cue = sum(1 for c in self.show.cues if c.t < t)
        return t

    def _play(self, show_t: float) -> None:
        path = self.show.audio_path()
        assert path is not None
        skip = self.show.audio_time(show_t)
        try:
            cmd, stdin = player_command(path, skip, self.player)
            data = wav_from(path, skip) if stdin else b""
            proc = subprocess.Popen(cmd, stdin=subprocess.PIPE if stdin else None,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        except (ConfigError, OSError) as e:
            self._warn(str(e))
            return
        self._proc = proc
        _, err = proc.communicate(data if stdin else None)
        if proc is not self._proc:           # superseded by a seek (a chased jump)
            return
        if proc.returncode not in (0, None) and not self._done.is_set():
            first = err.decode(errors="replace").strip().splitlines()[:1]
            self._warn(f"audio {path}: {cmd[0]} exited {proc.returncode}"
                       + (f": {first[0]}" if first else "") + " (no audio device?)")

    def _warn(self, text: str) -> None:
        self.warning = f"{text}; the show runs silent"
        log.warning(self.warning)

    def close(self) -> None:
        """Stop the player (the show ended or was stopped)."""
        self._done.set()
        self._stop_player()

    def _stop_player(self) -> None:
        if self._proc is not None:
            _end(self._proc)
        if self._thread is not None:
            self._thread.join(timeout=2.0)


def _end(proc: subprocess.Popen[bytes]) -> None:
    """Stop a player process (terminate, then kill after 2 s)."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:
            proc.kill()
