"""Issue 36, row 1 and row 6: a failed start never eats a take; every command writes its
output whole (robot/files/atomic.py) or not at all.

- A run that never starts (the port does not open; a joint outside its limits) leaves the
  take or record already at ``--record`` byte for byte, and no temporary file.
- A run that started and was stopped (Ctrl-C) leaves the whole take: every line JSON,
  ending at rest. One that filled the disk leaves the lines that fitted, each whole.
- Every command that writes a file, on a disk with a few kilobytes left (its output check
  passes, the write fails part-way): one line naming the file and "No space left on
  device", exit 2, the old file as it was, nothing else in the folder.
- `render` onto /dev/full says so and exits 2, as `export` does.
"""

from __future__ import annotations

import json
import os
import signal
from collections.abc import Callable
from pathlib import Path

import pytest
from anim_files import write_blender_bvh
from bus_harness import PATIENT_TIMEOUT_MS
from command_ends import Biped
from full_disk import LEFT
from test_bad_input import assert_refused, run_cli
from test_end_paths import ticks_of
from test_keyframes import WAVE

import robot.cli as cli
from robot.config.robot import RobotConfig
from robot.motion.takes import read_take
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness", "full_disk")

REPLY_TIMEOUT_MS = PATIENT_TIMEOUT_MS
OLD = "the old file, whole\n"


def names(d: Path) -> list[str]:
    return sorted(p.name for p in d.iterdir())


@pytest.fixture(scope="module")
def good(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    """A good take and a good CSV record of a short sim walk, as bytes."""
    d = tmp_path_factory.mktemp("good")
    out = {}
    for name in ("keep.take.jsonl", "keep.csv"):
        assert cli.main(["walk", "--seconds", "0.3", "--record", str(d / name)]) == 0
        out[name] = (d / name).read_bytes()
        assert len(out[name]) > 10_000
    return out


@pytest.mark.parametrize("name", ["keep.take.jsonl", "keep.csv"])
def test_a_port_that_does_not_open_keeps_the_record(
        name: str, good: dict[str, bytes], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """It was cut to its 1.9 KB header: the file was opened for writing before the bus."""
    keep = tmp_path / name
    keep.write_bytes(good[name])
    code = cli.main(["walk", "--bus", "dynamixel", "--port", str(tmp_path / "nonexistent"),
                     "--record", str(keep)])
    err = capsys.readouterr().err
    assert code == 1 and "cannot open" in err, err
    assert keep.read_bytes() == good[name]
    assert names(tmp_path) == [name]


@pytest.mark.parametrize("protocol", ["feetech"], indirect=True)
@pytest.mark.parametrize(("command", "name"), [("walk", "keep.take.jsonl"),
                                             ("play", "keep.csv")])
def test_a_refused_start_keeps_the_record(command: str, name: str, emu: Emulator,
                                          robot: RobotConfig, robot_toml: Path,
                                          good: dict[str, bytes], tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    knee = robot.joint("r_knee")
    emu.set_register(knee.servo_id, "present_position",
                     ticks_of(robot, "r_knee", knee.max_rad + 0.3))
    keep = tmp_path / name
    keep.write_bytes(good[name])
    wave = tmp_path / "wave.toml"
    wave.write_text(WAVE)
    what = ["walk", "--seconds", "1"] if command == "walk" else ["play", str(wave)]
    code = cli.main([*what, "--bus", "feetech", "--port", emu.port, "--robot",
                     str(robot_toml), "--record", str(keep)])
    assert code == 1 and "refusing to start" in capsys.readouterr().err
    assert keep.read_bytes() == good[name]
    assert names(tmp_path) == sorted([name, "wave.toml", robot_toml.name])


def test_ctrl_c_leaves_the_whole_take(good: dict[str, bytes], tmp_path: Path) -> None:
    """SIGINT once the take is tens of kilobytes into its temporary file: the walk ramps
    out and rests, and the take is renamed onto the old one, every line whole."""
    keep = tmp_path / "keep.take.jsonl"
    keep.write_bytes(good["keep.take.jsonl"])
    p = Biped("walk", "--seconds", "600", "--record", str(keep))

    def grown() -> bool:
        return any(f.name.startswith(".keep.take.jsonl.") and f.stat().st_size > 65536
                   for f in tmp_path.iterdir())
    p.when(grown)
    p.proc.send_signal(signal.SIGINT)
    code, out, err = p.finish(timeout=120)
    assert code == 130, out + err
    lines = [json.loads(x) for x in keep.read_text().splitlines()]
    assert lines[0]["take"] == 1 and keep.read_bytes() != good["keep.take.jsonl"]
    ticks = [x for x in lines if "tick" in x]
    assert len(ticks) > 100 and ticks[-1]["state"] == "rest"
    assert read_take(keep).q.shape == (len(ticks), len(lines[0]["joints"]))
    assert names(tmp_path) == ["keep.take.jsonl"]


@pytest.mark.parametrize("name", ["run.take.jsonl", "run.csv"])
def test_a_disk_that_fills_during_the_run_keeps_the_whole_lines(
        name: str, nearly_full_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    record = nearly_full_dir / name
    code = cli.main(["walk", "--seconds", "2", "--json", "--record", str(record)])
    result = json.loads(capsys.readouterr().out)
    assert code == 1 and "No space left on device" in result["record_error"], result
    text = record.read_text()
    assert 0 < len(text) <= LEFT and text.endswith("\n")
    lines = text.splitlines()
    if name.endswith(".jsonl"):
        rows = [json.loads(x) for x in lines]
        assert rows[0]["take"] == 1 and all("tick" in r for r in rows[1:])
    else:
        width = len(lines[0].split(","))
        assert width > 40 and all(len(x.split(",")) == width for x in lines)
    assert len(lines) >= 2
    assert names(nearly_full_dir) == [".fill", name]


# --------------------------------------------------------- every command that writes
def _record_csv(tmp: Path) -> Path:
    path = tmp / "in.csv"
    assert cli.main(["walk", "--seconds", "0.3", "--record", str(path)]) == 0
    return path


def _bvh(tmp: Path) -> Path:
    path = tmp / "dance.bvh"
    write_blender_bvh(str(path), 24.0, 25)
    return path


#: command → (the file it writes, in the nearly full folder; argv from that file and a
#: folder of inputs). Each output is larger than the space left.
WRITERS: dict[str, tuple[str, Callable[[Path, Path], list[str]]]] = {
    "curves --out": ("c.csv", lambda o, t: ["curves", "--seconds", "2", "--out", str(o)]),
    "curves --plot": ("c.png", lambda o, t: ["curves", "--seconds", "1", "--out",
                                              str(t / "c.csv"), "--plot", str(o)]),
    "export bvh": ("x.bvh", lambda o, t: ["export", "--seconds", "1", "--out", str(o)]),
    "export glb": ("x.glb", lambda o, t: ["export", "--seconds", "2", "--out", str(o)]),
    "export gltf": ("x.gltf", lambda o, t: ["export", "--seconds", "2", "--out", str(o)]),
    "import": ("d.take.jsonl", lambda o, t: ["import", str(_bvh(t)), "--out", str(o)]),
    "plot": ("p.png", lambda o, t: ["plot", str(_record_csv(t)), "--out", str(o)]),
    "render mp4": ("r.mp4", lambda o, t: ["render", "--seconds", "0.3", "--quiet",
                                          "--out", str(o)]),
    "render gif": ("r.gif", lambda o, t: ["render", "--seconds", "0.3", "--quiet",
                                          "--width", "64", "--height", "48",
                                          "--out", str(o)]),
}


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_a_write_that_does_not_fit_keeps_the_old_file(
        command: str, nearly_full_dir: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    name, argv = WRITERS[command]
    out = nearly_full_dir / name
    out.write_text(OLD)
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    args = argv(out, inputs)
    capsys.readouterr()
    code, _, err = run_cli(args, capsys, monkeypatch)
    line = assert_refused(code, err, str(out))
    assert "no space left on device" in line.lower(), line
    assert out.read_text() == OLD
    assert names(nearly_full_dir) == [".fill", name]


def test_mjcf_that_does_not_fit_keeps_the_old_files(
        nearly_full_dir: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    out = nearly_full_dir / "m"
    out.mkdir()
    (out / "robot.xml").write_text(OLD)
    code, _, err = run_cli(["mjcf", "--out", str(out)], capsys, monkeypatch)
    assert_refused(code, err, str(out), "No space left on device")
    assert (out / "robot.xml").read_text() == OLD and names(out) == ["robot.xml"]


def test_a_robot_copy_that_does_not_fit_leaves_nothing(
        nearly_full_dir: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """The copy (5.4 kB) in the one page (4 kB) left beside another file."""
    (nearly_full_dir / "other.toml").write_text(OLD)
    dest = nearly_full_dir / "mine.toml"
    code, _, err = run_cli(["robots", "copy", "biped18-dynamixel", str(dest)], capsys,
                           monkeypatch)
    assert_refused(code, err, str(dest), "No space left on device")
    assert names(nearly_full_dir) == [".fill", "other.toml"]


@pytest.mark.parametrize("command", ["render", "export"])
def test_a_clip_onto_dev_full_is_refused(command: str, tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str],
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """render said `wrote full.mp4`, exit 0 (ffmpeg's error never reached it)."""
    out = tmp_path / ("full.mp4" if command == "render" else "full.glb")
    out.symlink_to("/dev/full")
    args = ([command, "--seconds", "0.2", "--quiet", "--out", str(out)] if command == "render"
            else [command, "--seconds", "0.2", "--out", str(out)])
    code, outs, err = run_cli(args, capsys, monkeypatch)
    assert_refused(code, err, f"--out {out}", "No space left on device")
    assert "wrote" not in outs
    assert os.path.islink(out) and names(tmp_path) == [out.name]
