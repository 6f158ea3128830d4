"""A show's soundtrack on the robot's computer (robot/loop/soundtrack.py): the player is
started once, when the show reaches the audio's start, with the WAV cut to the right
sample; cues are printed as the show passes them; with no player the show runs silent
with one warning. The player here is a stand-in at the process boundary: a script that
reads the WAV on stdin as aplay does and writes down what it got."""

from __future__ import annotations

import json
import math
import sys
import wave
from pathlib import Path

import numpy as np
import pytest

import robot.cli as cli
from robot.loop.soundtrack import Soundtrack
from robot.loop.telemetry import Telemetry
from robot.motion.show import Cue, Show

RATE = 8000
PLAYER = """
import sys, io, wave, json, time
data = sys.stdin.buffer.read()
w = wave.open(io.BytesIO(data), "rb")
json.dump({"frames": w.getnframes(), "rate": w.getframerate(), "at": time.monotonic()},
          open(sys.argv[1], "w"))
"""


def _wav(path: Path, seconds: float) -> None:
    t = np.arange(int(seconds * RATE)) / RATE
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(RATE)
        w.writeframes((0.2 * np.sin(2 * math.pi * 440 * t) * 32767).astype("<i2").tobytes())


def _keys(path: Path, audio: str, offset: float, cues: list[tuple[float, str]]) -> None:
    lines = ['name = "wave"', "", "[show]", f'audio = "{audio}"', f"audio_offset_s = {offset}"]
    for t, name in cues:
        lines += ["[[show.cue]]", f"t = {t}", f'name = "{name}"']
    lines += ["", "[[keyframe]]", "t = 0.0", "r_shoulder_pitch = 0.0",
              "[[keyframe]]", "t = 1.5", "r_shoulder_pitch = -0.8"]
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize(("offset", "skipped_s"), [(-1.0, 1.0), (0.5, 0.0)])
def test_the_player_starts_at_the_audio_offset_with_the_wav_cut(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], offset: float,
        skipped_s: float) -> None:
    _wav(tmp_path / "song.wav", 3.0)
    keys = tmp_path / "wave.keys.toml"
    _keys(keys, "song.wav", offset, [(0.25, "lights"), (1.0, "bow")])
    got = tmp_path / "player.json"
    script = tmp_path / "player.py"
    script.write_text(PLAYER)
    code = cli.main(["play", str(keys), "--player", f"{sys.executable} {script} {got}"])
    assert code == 0
    out = capsys.readouterr().out
    assert "cue 0.25 s: lights" in out and "cue 1.00 s: bow" in out
    assert out.index("lights") < out.index("bow")
    heard = json.loads(got.read_text())
    assert heard["rate"] == RATE
    assert heard["frames"] == int(round((3.0 - skipped_s) * RATE))


def test_the_soundtrack_follows_show_time_not_the_ramp_in(tmp_path: Path) -> None:
    _wav(tmp_path / "song.wav", 1.0)
    track = Soundtrack(Show(audio="song.wav", audio_offset_s=0.3, base=str(tmp_path),
                            cues=(Cue(0.1, "a"),)), player="true")
    seen: list[str] = []
    track.on_cue = lambda c: seen.append(c.name)
    for k in range(100):                 # 0.2 s of ramp in, then the show, at 100 Hz
        track(Telemetry(t=k / 100, state="ramp_in" if k < 20 else "walking", tick=k))
    track.close()
    assert track.start == pytest.approx(0.2)
    assert track.started_at == pytest.approx(0.3, abs=0.011)
    assert seen == ["a"]


def test_no_player_runs_the_show_silent_with_one_warning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        caplog: pytest.LogCaptureFixture) -> None:
    _wav(tmp_path / "song.wav", 1.0)
    keys = tmp_path / "wave.keys.toml"
    _keys(keys, "song.wav", 0.0, [])
    code = cli.main(["play", str(keys), "--json", "--player", str(tmp_path / "no-such-player")])
    assert code == 0
    said = capsys.readouterr()
    result = json.loads(said.out)
    assert result["stop_reason"] == "completed"
    assert "runs silent" in result["audio"]["warning"]
    assert [r.levelname for r in caplog.records if "runs silent" in r.message] == ["WARNING"]


def test_a_chased_jump_restarts_the_player_there_and_the_cues_from_there(
        tmp_path: Path) -> None:
    """A chased show (``clock``: its show time): a jump from 0.5 s to 2.0 s restarts the
    player with the WAV cut at 2.0 s; the cue the jump passed over is not fired, the one
    after it is; a jump back fires the passed cue again."""
    from waiting import wait_for
    _wav(tmp_path / "song.wav", 3.0)
    log = tmp_path / "heard.jsonl"
    script = tmp_path / "player.py"
    script.write_text("import sys, io, wave, json\n"
                      "w = wave.open(io.BytesIO(sys.stdin.buffer.read()), 'rb')\n"
                      f"open({str(log)!r}, 'a').write(json.dumps(w.getnframes()) + '\\n')\n")
    track = Soundtrack(Show(audio="song.wav", base=str(tmp_path),
                            cues=(Cue(0.2, "a"), Cue(1.0, "skipped"), Cue(2.2, "b"))),
                       player=f"{sys.executable} {script}")
    seen: list[str] = []
    track.on_cue = lambda c: seen.append(c.name)
    show_t = [0.0]
    track.clock = lambda: show_t[0]

    def lines() -> list[int]:
        return [int(v) for v in log.read_text().split()] if log.exists() else []
    for k in range(60):                                  # 0 .. 0.59 s at 100 Hz
        show_t[0] = k / 100
        track(Telemetry(t=k / 100, state="walking", tick=k))
    assert wait_for(lambda: len(lines()) == 1)
    for k in range(60, 100):                             # jumped: 2.0 .. 2.39 s
        show_t[0] = 2.0 + (k - 60) / 100
        track(Telemetry(t=k / 100, state="walking", tick=k))
    assert wait_for(lambda: len(lines()) == 2)
    assert lines() == [3 * RATE, 1 * RATE]               # the whole song, then from 2.0 s
    assert seen == ["a", "b"]
    show_t[0] = 0.1                                      # and back
    track(Telemetry(t=1.0, state="walking", tick=100))
    show_t[0] = 0.3
    track(Telemetry(t=1.2, state="walking", tick=101))
    track.close()
    assert seen == ["a", "b", "a"]


def _refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    try:
        code = cli.main(argv)
    except SystemExit as e:
        code = int(e.code or 0)
    out, err = capsys.readouterr()
    assert code == 2 and out == "", out + err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err.strip()


@pytest.mark.parametrize("value", ["nan", "inf", "-1e400", "1e7"])
@pytest.mark.parametrize("command", ["import", "play"])
def test_an_audio_offset_that_is_no_time_is_refused_at_the_flag(
        command: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 36: import wrote "audio_offset_s": NaN, which play then refused."""
    keys = tmp_path / "wave.keys.toml"
    _keys(keys, "song.wav", 0.0, [])
    _wav(tmp_path / "song.wav", 0.5)
    argv = (["import", str(tmp_path / "none.bvh"), "--out", str(tmp_path / "o.take.jsonl")]
            if command == "import" else ["play", str(keys)])
    err = _refused([*argv, f"--audio-offset={value}"], capsys)
    assert "argument --audio-offset" in err and "[-1e+06, 1e+06] s" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["song.wav", "wave.keys.toml"]


@pytest.mark.parametrize(("data", "why"), [
    (b"", "it ends before its header is whole"),
    (b"not a sound\n" * 20, "file does not start with RIFF id"),
])
def test_a_wav_that_does_not_read_is_refused_with_its_reason(
        data: bytes, why: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 36: "not a readable WAV file: ;" with no reason, a silent show, exit 0."""
    keys = tmp_path / "wave.keys.toml"
    _keys(keys, "song.wav", 0.0, [])
    bad = tmp_path / "text.wav"
    bad.write_bytes(data)
    err = _refused(["play", str(keys), "--audio", str(bad)], capsys)
    assert f"audio {bad}: not a readable WAV file: {why}" in err, err
