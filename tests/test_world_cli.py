"""`biped walk` perturbation options: validation (one line, exit 2, nothing opened), sim
only, and the "world" object of the JSON summary (a short walk)."""

from __future__ import annotations

import json

import pytest

from robot import cli


def run_walk(argv: list[str], capsys: pytest.CaptureFixture[str],
             monkeypatch: pytest.MonkeyPatch) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``biped walk <argv>`` in-process (only `walk` built)."""
    monkeypatch.setattr(cli, "COMMANDS", ("walk",))
    try:
        code = cli.main(["walk", *argv])
    except SystemExit as e:
        code = int(e.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(("argv", "needles"), [
    (["--slope", "30"], ("--slope", "'30'", "[-20, 20] deg")),
    (["--cross-slope", "-21"], ("--cross-slope", "'-21'", "[-20, 20] deg")),
    (["--bumps", "-1"], ("--bumps", "'-1'", "[0, 50] mm")),
    (["--bumps", "nan"], ("--bumps", "'nan'", "[0, 50] mm")),
    (["--terrain-seed", "x"], ("--terrain-seed", "'x'", "[0, 2147483647]")),
    (["--push", "3:20,0"], ("--push", "'3:20,0'", "[-10, 10] N*s")),
    (["--push", "3"], ("--push", "'3'", "T:JX,JY")),
    (["--push=-1:1,0"], ("--push", "'-1:1,0'", "[0, 1e+06] s")),
    (["--latency", "150"], ("--latency", "'150'", "[0, 100] ms")),
    (["--friction", "0.1"], ("--friction", "'0.1'", "[0.2, 3]")),
    (["--mass-scale", "2.5"], ("--mass-scale", "'2.5'", "[0.5, 2]")),
    (["--stairs", "0.015"], ("--stairs", "'0.015'", "H,N")),
    (["--stairs", "0.06,3"], ("--stairs", "'0.06,3'", "(0, 0.05] m")),
    (["--stairs", "0,3"], ("--stairs", "'0,3'", "(0, 0.05] m")),
    (["--stairs", "0.015,0"], ("--stairs", "'0.015,0'", "[1, 10]")),
    (["--stairs", "0.015,2.5"], ("--stairs", "'0.015,2.5'", "[1, 10]")),
    (["--stairs", "0.015,3,0.01"], ("--stairs", "'0.015,3,0.01'", "TREAD in [0.05, 1] m")),
    (["--stairs", "0.015,3,0.2,1"], ("--stairs", "'0.015,3,0.2,1'", "H,N[,TREAD]")),
    (["--switch", "x:jog"], ("--switch", "'x:jog'", "T:PRESET")),
    (["--switch", "3:"], ("--switch", "'3:'", "T:PRESET")),
])
def test_a_bad_value_is_one_line_naming_option_value_and_range(
        argv: list[str], needles: tuple[str, ...], capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    code, out, err = run_walk(["--json", *argv], capsys, monkeypatch)
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    for needle in needles:
        assert needle in err, (needle, err)


def test_perturbations_are_refused_on_a_real_bus(capsys: pytest.CaptureFixture[str],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    code, out, err = run_walk(["--bus", "dynamixel", "--port", "/dev/null/none",
                               "--latency", "20"], capsys, monkeypatch)
    assert code == 2 and out == ""
    assert err.splitlines() == [
        "biped walk: error: --latency applies to --bus sim only, not --bus dynamixel"]


def test_json_reports_the_world_and_the_pushes(capsys: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    code, out, err = run_walk(
        ["--json", "--seconds", "1", "--no-balance", "--slope", "3", "--cross-slope", "-2",
         "--latency", "10", "--friction", "1.5", "--mass-scale", "0.9",
         "--push", "0.5:0.1,-0.05", "--push", "0.2:0,0.1"], capsys, monkeypatch)
    assert code == 0, err
    r = json.loads(out)
    assert r["fell"] is False and r["fell_at_s"] is None
    w = r["world"]
    assert (w["slope_deg"], w["cross_slope_deg"], w["latency_s"], w["friction_scale"],
            w["mass_scale"], w["bumps_mm"]) == (3.0, -2.0, 0.01, 1.5, 0.9, 0.0)
    assert w["pushes"] == [{"at_s": 0.2, "jx": 0.0, "jy": 0.1},
                           {"at_s": 0.5, "jx": 0.1, "jy": -0.05}]
    applied = w["pushes_applied"]
    assert [p["at_s"] for p in applied] == [0.2, 0.5]
    assert applied[1]["sim_t_s"] - applied[0]["sim_t_s"] == pytest.approx(0.3, abs=0.006)


def test_json_world_defaults_without_options(capsys: pytest.CaptureFixture[str],
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    code, out, err = run_walk(["--json", "--seconds", "0.5", "--no-balance"], capsys,
                              monkeypatch)
    assert code == 0, err
    w = json.loads(out)["world"]
    assert w == {"slope_deg": 0.0, "cross_slope_deg": 0.0, "bumps_mm": 0.0,
                 "terrain_seed": 0, "pushes": [], "latency_s": 0.0, "friction_scale": 1.0,
                 "mass_scale": 1.0, "stairs_height_m": 0.0, "stairs_count": 0, "stairs_tread_m": 0.25,
                 "pushes_applied": []}


def test_stop_on_fall_ends_the_walk_at_the_fall(capsys: pytest.CaptureFixture[str],
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """A 3 N*s shove backward 1 s into the gait topples the robot; --stop-on-fall ends the
    run there (torque off) instead of lying on the floor for the rest of the 6 s."""
    argv = ["--json", "--seconds", "6", "--no-balance", "--push", "1:-3,0"]
    _, out, _ = run_walk(argv, capsys, monkeypatch)
    whole = json.loads(out)
    code, out, _ = run_walk([*argv, "--stop-on-fall"], capsys, monkeypatch)
    short = json.loads(out)
    assert whole["fell"] and short["fell"] and short["fell_at_s"] == whole["fell_at_s"]
    assert short["stop_reason"] == "fell" and whole["stop_reason"] == "completed"
    assert short["ticks"] < whole["ticks"] - 200 * 3        # over 3 s of ticks saved
    assert code == 0


def test_stop_on_fall_is_refused_on_a_real_bus(capsys: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    code, out, err = run_walk(["--bus", "feetech", "--port", "/dev/null/none",
                               "--stop-on-fall"], capsys, monkeypatch)
    assert code == 2 and out == "" and len(err.splitlines()) == 1
    assert "--stop-on-fall apply to --bus sim only" in err
