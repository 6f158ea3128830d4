"""`biped identify` on the logs a pendulum rig produces when something goes wrong (issue
35): each bad or odd log is one line naming the file and the field, exit 2, nothing written
(no model, no plot), never a traceback and never a NaN in what is printed or written.

Oracles: the issue's table (the message it gives; the field and the index a reader would
look for), the public recordings in ../shared/servo_logs/bam/ (what a good log is: every
one of them still loads), and the manuals' register ranges as robot/servo/gains.py
transcribes them (XL330's Position P Gain 0 ~ 16,383; the STS P coefficient one byte).
"""

from __future__ import annotations

import gzip
import json
import math
from pathlib import Path

import pytest

from robot import cli
from robot.servo.pendulum_log import read_log

BAM = Path(__file__).resolve().parents[1].parent / "shared" / "servo_logs" / "bam"
MODEL_OF = {"xl330": "XL330-M288", "sts3250": "STS3250"}


def _log(**head: object) -> dict[str, object]:
    """A good log: 1 s of a 1 Hz swing at 5 ms, 0.3 kg at 0.1 m, P 400 (the keys of
    ``head`` replace the top-level fields)."""
    entries = []
    for i in range(200):
        t = i * 0.005
        q = 0.5 * math.sin(2 * math.pi * t)
        entries.append({"timestamp": round(t, 6), "goal_position": q, "position": 0.9 * q,
                        "speed": 0.9 * math.pi * math.cos(2 * math.pi * t), "load": 0.1,
                        "input_volts": 7.4, "temp": 30.0, "torque_enable": True})
    return {"mass": 0.3, "length": 0.1, "kp": 400, "vin": 7.4, "motor": "xl330",
            "trajectory": "sin", **head, "entries": entries}


def _write(path: Path, data: object) -> Path:
    # json.dumps writes NaN and Infinity as JavaScript does (and as a Python recorder
    # would); json.loads reads them back
    path.write_text(json.dumps(data))
    return path


def _refused(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    """Run ``biped ARGV``: exit 2, nothing on stdout, one line on stderr (returned)."""
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1, (out, err)
    assert "Traceback" not in err
    return err.strip()


def _check(log: Path, *more: str) -> list[str]:
    return ["identify", "check", str(log), "--model", "XL330-M288", *more]


# ------------------------------------------------------------------------- the rows


@pytest.mark.parametrize("field, value, shown", [
    ("mass", float("nan"), "nan"), ("mass", -1, "-1"), ("length", float("inf"), "inf"),
])
def test_check_refuses_a_mass_or_length_that_is_not_a_finite_positive_number(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], field: str, value: float,
        shown: str) -> None:
    bad = _write(tmp_path / "bad.json", _log(**{field: value}))
    plot = tmp_path / "check.png"
    err = _refused(capsys, _check(bad, "--plot", str(plot)))
    assert err.endswith(f"{bad}: {field} must be a finite number > 0 (got {shown})")
    assert not plot.exists()


@pytest.mark.parametrize("field", ["position", "goal_position"])
def test_check_refuses_a_non_finite_sample_naming_its_index(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], field: str) -> None:
    data = _log()
    data["entries"][117][field] = float("nan")     # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    err = _refused(capsys, _check(bad, "--json"))
    assert err.endswith(f"{bad}: entries[117].{field} must be a finite number (got nan)")


def test_check_refuses_an_implausible_duration(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    data = _log()
    data["entries"][-1]["timestamp"] = 1e9          # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    err = _refused(capsys, _check(bad))
    assert f"{bad}: duration must be at most " in err and "(got 1e+09 s)" in err


@pytest.mark.parametrize("model, kp, span", [
    ("XL330-M288", 1e300, "0..16383"),     # the row: no register holds it
    ("XL330-M288", 16384, "0..16383"),     # Position P Gain(84): 0 ~ 16,383
    ("XL330-M288", 12.5, "0..16383"),      # a register holds an integer
    ("STS3250", 400, "0..254"),            # P coefficient(21): one byte
])
def test_check_refuses_a_kp_outside_its_register(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], model: str, kp: float,
        span: str) -> None:
    bad = _write(tmp_path / "bad.json", _log(kp=kp))
    err = _refused(capsys, ["identify", "check", str(bad), "--model", model])
    assert f"{bad}: kp must be an integer in {span}" in err and f"(got {kp:g})" in err
    assert len(err) < 200          # no 300-digit integer


def test_fit_with_one_log_and_the_default_holdout_says_what_to_do(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    good = _write(tmp_path / "one.json", _log())
    out = tmp_path / "o.toml"
    err = _refused(capsys, ["identify", "fit", str(good), "--motor", "XL330-M288",
                            "--trials", "10", "--out", str(out)])
    assert err.endswith("need at least 2 logs with --holdout > 0 (or --holdout 0)")
    assert not out.exists()


def test_fit_refuses_a_nan_log_and_writes_no_model(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    data = _log()
    data["entries"][40]["position"] = float("nan")  # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    good = _write(tmp_path / "good.json", _log())
    out = tmp_path / "o.toml"
    err = _refused(capsys, ["identify", "fit", str(good), str(bad), "--motor", "XL330-M288",
                            "--trials", "10", "--holdout", "0", "--out", str(out)])
    assert err.endswith(f"{bad}: entries[40].position must be a finite number (got nan)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json", "good.json"]


# ----------------------------------------------------------- the other rules, written once


@pytest.mark.parametrize("change, message", [
    (("timestamp", 5, 0.02), "entries[5].timestamp must be later than entries[4]'s"),
    (("timestamp", 0, float("inf")), "entries[0].timestamp must be a finite number (got inf)"),
    (("speed", 3, float("-inf")), "entries[3].speed must be a finite number (got -inf)"),
    (("temp", 9, float("nan")), "entries[9].temp must be a finite number (got nan)"),
    (("torque_enable", 2, "false"), "entries[2].torque_enable must be true or false"),
    # MuJoCo's replay resets on these ("the simulation is unstable") and prints an error
    # that means nothing
    (("position", 0, 1e12), "entries[0].position must be within +-6.28 rad (got 1e+12)"),
    (("goal_position", 8, -40.0), "entries[8].goal_position must be within +-6.28 rad"),
    (("speed", 0, 1e300), "entries[0].speed must be within +-100 rad/s (got 1e+300)"),
])
def test_a_sample_is_refused_by_its_field_and_index(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        change: tuple[str, int, object], message: str) -> None:
    field, i, value = change
    data = _log()
    data["entries"][i][field] = value               # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    err = _refused(capsys, _check(bad))
    assert f"{bad}: {message}" in err


@pytest.mark.parametrize("head, message", [
    ({"vin": float("nan")}, "vin must be a finite number > 0 (got nan)"),
    ({"vin": 0}, "vin must be a finite number > 0 (got 0)"),
    ({"vin": 240}, "vin must be at most"),
    ({"mass": 1e-300}, "mass must be at least"),      # MuJoCo refuses so light a body
    ({"mass": 50}, "mass must be at most 10 kg (got 50)"),
    ({"length": 0}, "length must be a finite number > 0 (got 0)"),
    ({"arm_mass": -0.1}, "arm_mass must be a finite number >= 0 (got -0.1)"),
    ({"kp": -3}, "kp must be an integer in 0..16383"),
    ({"kp": float("nan")}, "kp must be an integer in 0..16383"),
    ({"kp": 10 ** 400}, "kp must be an integer in 0..16383"),
])
def test_a_header_field_is_refused_by_name(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                           head: dict[str, object], message: str) -> None:
    bad = _write(tmp_path / "bad.json", _log(**head))
    err = _refused(capsys, _check(bad))
    assert f"{bad}: {message}" in err


def test_a_log_shorter_than_the_shortest_run_is_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _log()
    data["entries"] = data["entries"][:4]           # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    err = _refused(capsys, _check(bad))
    assert f"{bad}: duration must be at least " in err and "(got 0.015 s)" in err


def test_record_refuses_a_weight_the_logs_would_refuse_before_opening_a_port(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The same rules: --mass 0 would write logs every reader refuses; --kp above the
    register never reaches the servo (no port is opened: /dev/null is no servo bus)."""
    base = ["identify", "record", "--bus", "dynamixel", "--port", "/dev/null", "--id", "1",
            "--motor", "XL330-M288", "--length", "0.1", "--out", str(tmp_path / "logs")]
    err = _refused(capsys, [*base, "--mass", "0"])
    assert err.endswith("--mass must be a finite number > 0 (got 0)")
    err = _refused(capsys, [*base, "--mass", "0.3", "--kp", "400,20000"])
    assert "--kp must be an integer in 0..16383" in err and err.endswith("(got 20000)")
    assert not (tmp_path / "logs").exists()


def test_every_public_recording_still_loads(tmp_path: Path) -> None:
    """What a good log is: the 20 recordings of Rhoban/bam's rigs pass every rule with the
    gain set of the model they are of."""
    paths = sorted(BAM.glob("*/*.json.gz"))
    assert len(paths) == 20
    for path in paths:
        from robot.config.servo_file import physics_for

        log = read_log(path, law=physics_for(MODEL_OF[path.parent.name]).law)
        assert log.mass > 0 and 5.9 < log.t[-1] < 6.0, path


# ---------------------------------------------------------------- held already (kept)


def _gz(path: Path, raw: bytes) -> Path:
    path.write_bytes(raw)
    return path


@pytest.mark.parametrize("name, content, message", [
    ("empty.json", b"", "not a JSON pendulum log"),
    ("empty.json.gz", b"", "not a JSON pendulum log"),
    ("cut.json.gz", gzip.compress(json.dumps(_log()).encode())[:300], "cannot read"),
    ("list.json", b"[1, 2]", "expected a JSON object with 'entries'"),
    ("entries.json", b'{"entries": {"timestamp": 0}}', "entries: expected a list"),
    ("entry.json", json.dumps({**_log(), "entries": [1, 2]}).encode(),
     "entries[0]: expected an object"),
    ("one.json", json.dumps({**_log(), "entries": _log()["entries"][:1]}).encode(),  # type: ignore[index]
     "at least 2 samples"),
    ("nomass.json", json.dumps({k: v for k, v in _log().items() if k != "mass"}).encode(),
     "mass: expected a number, got None"),
])
def test_held_already_an_unreadable_log_is_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, content: bytes,
        message: str) -> None:
    bad = _gz(tmp_path / name, content)
    err = _refused(capsys, _check(bad))
    assert str(bad) in err and message in err


def test_held_already_a_missing_sample_field_names_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _log()
    del data["entries"][7]["goal_position"]         # type: ignore[index]
    bad = _write(tmp_path / "bad.json", data)
    err = _refused(capsys, _check(bad))
    assert f"{bad}: entries[7]: goal_position: expected a number, got None" in err


@pytest.mark.parametrize("argv, message", [
    (["check", "{log}", "--model", "XL999"], "--model: expected a servo model"),
    (["fit", "{log}", "{log}", "--motor", "XL999", "--out", "{out}"], "--motor: expected one of"),
    (["fit", "{log}", "{log}", "--motor", "XL330-M288", "--trials", "5", "--out", "{out}"],
     "--trials: expected at least 10, got 5"),
])
def test_held_already_a_bad_option_is_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str],
        message: str) -> None:
    good = _write(tmp_path / "good.json", _log())
    out = tmp_path / "o.toml"
    err = _refused(capsys, ["identify", *(a.format(log=good, out=out) for a in argv)])
    assert message in err and not out.exists()


def test_sim_gap_refuses_a_load_the_rig_rule_refuses(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """sim-gap's --load keeps the same rule as a log's mass (0: nothing on the arm): a
    weight of 1e-300 kg is one line, where MuJoCo's replay would refuse the body."""
    take = tmp_path / "walk.take.jsonl"
    assert cli.main(["walk", "--seconds", "0.2", "--record", str(take)]) == 0
    capsys.readouterr()
    err = _refused(capsys, ["sim-gap", str(take), "--world", "bench",
                            "--load", "r_knee=1e-300@0.1"])
    assert err.endswith("--load r_knee=1e-300@0.1: mass must be at least 0.001 kg "
                        "(got 1e-300)")
