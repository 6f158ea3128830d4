"""Issue 19 items 7, 10, 11: inputs that gave a traceback (or were taken) are one line and
exit 2, naming the file or option and the field, and nothing moves: a take or keyframe
file with a 5000-digit number or deep nesting; `biped plot` on files that are not records;
``--out`` on a full disk (checked before the work); a 400-digit ``--seed``; an empty gait
file and a header-only take; a read-back interval that would switch the watchdog off; a
name ending in a newline.

Valid ranges are written out here by hand (the documented contract).
"""

from __future__ import annotations

import csv
import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from test_bad_input import assert_refused, base_robot, received, run_cli

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.panel.presets import check_name
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness", "full_disk")

DIGITS_5000 = "9" * 5000
DEEP = "[" * 100_000 + "]" * 100_000
TAKE_HEADER = {"take": 1, "robot": "biped18-dynamixel", "robot_file": "",
               "joints": list(load_robot(ROBOTS_DIR / "biped18-dynamixel.toml").joint_names),
               "rate_hz": 200, "read_every": 10, "gait": "walk", "params": {}, "bus": "sim"}


@pytest.fixture(scope="module")
def chain() -> Iterator[Emulator]:
    """One emulated Dynamixel chain for the module; each test compares byte counters."""
    with Emulator("dynamixel", load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")) as e:
        yield e


def on_the_chain(chain: Emulator, tmp_path: Path) -> list[str]:
    robot = tmp_path / "robot.toml"
    robot.write_text(base_robot("dynamixel"))
    return ["--bus", "dynamixel", "--port", chain.port, "--robot", str(robot)]


def take_file(tmp_path: Path, *lines: str) -> Path:
    path = tmp_path / "bad.take.jsonl"
    path.write_text("".join(line + "\n" for line in lines))
    return path


# ------------------------------------------------------------------ takes and keyframes
TAKES = {
    "5000-digit number in the header": (
        json.dumps(TAKE_HEADER).replace('"rate_hz": 200', f'"rate_hz": {DIGITS_5000}'),
        "line 1: not JSON: an integer has more than 4300 digits"),
    "5000-digit number in a tick": (
        json.dumps(TAKE_HEADER) + "\n" + '{"tick": 0, "q": [' + DIGITS_5000 + "]}",
        "line 2: not JSON: an integer has more than 4300 digits"),
    "deep nesting": (DEEP, "line 1: not JSON: arrays or objects nested too deeply"),
    "read_every 1e300": (json.dumps({**TAKE_HEADER, "read_every": 1e300}),
                         "line 1: read_every: expected an integer in [1, 100] at 200 Hz"),
    "read_every of 300 digits": (
        json.dumps(TAKE_HEADER).replace('"read_every": 10', '"read_every": 1' + "0" * 300),
        "line 1: read_every: expected an integer in [1, 100] at 200 Hz"),
    "header only": (json.dumps(TAKE_HEADER), "a header only"),
}


@pytest.mark.parametrize("case", sorted(TAKES))
def test_bad_take_is_one_line_for_play_on_the_bus(case: str, chain: Emulator, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    text, needle = TAKES[case]
    path = take_file(tmp_path, text)
    before = received(chain)
    code, out, err = run_cli(["play", str(path), *on_the_chain(chain, tmp_path)], capsys,
                             monkeypatch)
    assert_refused(code, err, f"{path}: ", needle)
    assert received(chain) == before                   # nothing reached the servos


@pytest.mark.parametrize("case", ["5000-digit number in a tick", "deep nesting"])
def test_bad_take_is_one_line_for_export(case: str, tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str],
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    text, needle = TAKES[case]
    path = take_file(tmp_path, text)
    code, _, err = run_cli(["export", "--take", str(path), "--out", str(tmp_path / "x.bvh")],
                           capsys, monkeypatch)
    assert_refused(code, err, f"{path}: ", needle)
    assert not (tmp_path / "x.bvh").exists()


KEYFRAMES = {
    "json 5000 digits": ("keys.json", '{"name": "k", "keyframe": [{"t": ' + DIGITS_5000 + "}]}",
                         "not JSON: an integer has more than 4300 digits"),
    "json deep": ("keys.json", DEEP, "not JSON: arrays or objects nested too deeply"),
    "toml 5000 digits": ("keys.toml", f"name = \"k\"\n[[keyframe]]\nt = {DIGITS_5000}\n",
                         "an integer has more than 4300 digits"),
    "toml deep": ("keys.toml", "x = " + "[" * 5000 + "]" * 5000 + "\n", "nested too deeply"),
}


@pytest.mark.parametrize("case", sorted(KEYFRAMES))
@pytest.mark.parametrize("command", ["play", "walk"])
def test_bad_keyframe_file_is_one_line(case: str, command: str, chain: Emulator,
                                       tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    name, text, needle = KEYFRAMES[case]
    path = tmp_path / name
    path.write_text(text)
    argv = (["play", str(path)] if command == "play"
            else ["walk", "--seconds", "1", "--keyframes", str(path)])
    before = received(chain)
    code, _, err = run_cli([*argv, *on_the_chain(chain, tmp_path)], capsys, monkeypatch)
    assert_refused(code, err, str(path), needle)
    assert received(chain) == before


# ------------------------------------------------------------------------------ plot
@pytest.fixture(scope="module")
def record_header(tmp_path_factory: pytest.TempPathFactory) -> list[str]:
    """The columns of a real `biped walk --record` CSV (a short walk on the sim bus)."""
    import robot.cli as cli
    path = tmp_path_factory.mktemp("record") / "run.csv"
    assert cli.main(["walk", "--seconds", "0.2", "--record", str(path)]) == 0
    with path.open(newline="") as f:
        return next(csv.reader(f))


def csv_text(header: list[str], rows: list[list[str]]) -> str:
    return "\n".join(",".join(r) for r in [header, *rows]) + "\n"


PLOTS = {  # name: (suffix, text from the record's header, needle)
    "one row": (".csv", lambda h: csv_text(h, [["0.1"] * len(h)]),
                "1 row; a plot needs at least 2"),
    "text": (".csv", lambda h: csv_text(h, [["abc"] * len(h)] * 3),
             "row 1: column 't': expected a finite time [s], got 'abc'"),
    "NaN": (".csv", lambda h: csv_text(h, [["nan"] * len(h)] * 3),
            "row 1: column 't': expected a finite time [s], got 'nan'"),
    "NUL": (".csv", lambda h: csv_text(h, [["0.1"] + ["\0"] * (len(h) - 1)] * 3),
            "expected a number or a word, got a NUL byte"),
    "huge field": (".csv", lambda h: csv_text(h, [["1" * 200_000]] * 3),
                   "field larger than field limit"),
    "nested JSON": (".jsonl", lambda h: '{"t": 0.0, "cmd_r_knee": {"a": [1]}}\n' * 3,
                    "column 'cmd_r_knee': expected a number or a word, got a nested dict"),
    "not objects": (".jsonl", lambda h: "[1, 2]\n" * 3,
                    "line 1: expected a JSON object (one row), got list"),
    "5000 digits": (".jsonl", lambda h: '{"t": ' + DIGITS_5000 + "}\n",
                    "line 1: not JSON: an integer has more than 4300 digits"),
}


@pytest.mark.parametrize("case", sorted(PLOTS))
def test_plot_of_a_file_that_is_not_a_record(case: str, record_header: list[str],
                                             tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    suffix, make, needle = PLOTS[case]
    path = tmp_path / f"bad{suffix}"
    path.write_text(make(record_header))
    code, _, err = run_cli(["plot", str(path), "--out", str(tmp_path / "o.png")], capsys,
                           monkeypatch)
    assert_refused(code, err, f"{path}: ", needle)
    assert not (tmp_path / "o.png").exists()


def test_plot_of_a_20_column_record_is_a_picture(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str],
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """t and 19 commanded joints, nothing else (no timing, no read-back): a traceback in
    the issue; a record plots what it has."""
    path = tmp_path / "wide.csv"
    path.write_text(csv_text(["t"] + [f"cmd_j{i}" for i in range(19)],
                             [[f"{0.1 * k:g}"] * 20 for k in range(3)]))
    code, out, err = run_cli(["plot", str(path), "--out", str(tmp_path / "o.png")], capsys,
                             monkeypatch)
    assert code == 0 and "Traceback" not in err, err
    assert (tmp_path / "o.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------------------------------ full disk
FULL_DISK = {
    "plot": lambda d, tmp: ["plot", str(tmp / "in.csv"), "--out", str(d / "o.png")],
    "curves": lambda d, tmp: ["curves", "--seconds", "1", "--out", str(d / "c.csv")],
    "export": lambda d, tmp: ["export", "--seconds", "1", "--out", str(d / "x.bvh")],
    "tune": lambda d, tmp: ["tune", "--trials", "2", "--out", str(d / "t.toml")],
    "walk --record": lambda d, tmp: ["walk", "--seconds", "1", "--record", str(d / "r.csv")],
}


@pytest.mark.parametrize("command", sorted(FULL_DISK))
def test_output_on_a_full_disk_is_refused_before_the_work(
        command: str, full_dir: Path, tmp_path: Path, record_header: list[str],
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """`tune` failed after 19 s of trials, the others with a traceback: the option is
    refused as argparse reads it (before a trial, a walk or a plot), one line."""
    (tmp_path / "in.csv").write_text(csv_text(record_header, [["0.1"] * len(record_header),
                                                               ["0.2"] * len(record_header)]))
    code, out, err = run_cli(FULL_DISK[command](full_dir, tmp_path), capsys, monkeypatch)
    option = "--record" if command == "walk --record" else "--out"
    assert_refused(code, err, option, f"no space left on the device of "
                   f"directory {full_dir}")
    assert out == ""
    assert sorted(p.name for p in full_dir.iterdir()) == [".fill"]


def test_tune_seed_of_400_digits(capsys: pytest.CaptureFixture[str],
                                 monkeypatch: pytest.MonkeyPatch) -> None:
    code, _, err = run_cli(["tune", "--seed", "1" * 400, "--trials", "1"], capsys, monkeypatch)
    assert_refused(code, err, "argument --seed", "expected a seed in [0, 2147483647]",
                   "(400 chars)")


# ------------------------------------------------------------------ presets and names
def test_empty_gait_file_is_refused(chain: Emulator, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """It walked on the defaults."""
    gait = tmp_path / "empty.toml"
    gait.write_text("# nothing yet\n")
    before = received(chain)
    code, _, err = run_cli(["walk", "--gait", str(gait), *on_the_chain(chain, tmp_path)],
                           capsys, monkeypatch)
    assert_refused(code, err, f"{gait}: no parameters")
    assert received(chain) == before


@pytest.mark.parametrize("name", ["walk\n", "take1\n", "ok\nx"])
def test_a_name_ending_in_a_newline_is_refused(name: str) -> None:
    """The rule ended in "$", which also matches before a final newline."""
    from robot.config.joint_names import EXTRA_NAME
    from robot.panel.studio import NAME_RE as TAKE_NAME
    with pytest.raises(ConfigError):
        check_name(name)
    assert TAKE_NAME.match(name) is None and EXTRA_NAME.match(name.lower()) is None


# ------------------------------------------------------------------ read-back interval
@pytest.mark.parametrize("value, rate, shown", [
    ("1e300", "200", "'1e300'"),
    ("1" + "0" * 300, "200", "(301 chars)"),
    ("1001", "2000", "'1001'"),                        # over 0.5 s even at the top rate
])
def test_read_every_that_would_blind_the_watchdog_at_parse(
        value: str, rate: str, shown: str, chain: Emulator, tmp_path: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    before = received(chain)
    code, _, err = run_cli(["walk", "--rate", rate, "--read-every", value,
                            *on_the_chain(chain, tmp_path)], capsys, monkeypatch)
    assert_refused(code, err, "argument --read-every", "in [1, 1000]", shown)
    assert received(chain) == before


def test_read_every_over_half_a_second_at_the_rate(chain: Emulator, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """101 ticks at 200 Hz: a read-back every 0.505 s (the bound is 0.5 s: 100 ticks)."""
    before = received(chain)
    code, _, err = run_cli(["walk", "--rate", "200", "--read-every", "101",
                            *on_the_chain(chain, tmp_path)], capsys, monkeypatch)
    assert_refused(code, err, "--read-every: expected an integer in [1, 100] at 200 Hz",
                   "got 101")
    assert received(chain) == before
