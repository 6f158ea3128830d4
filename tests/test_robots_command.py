"""`biped robots`: every bundled robot file on disk is listed with its bus, servos and
joints (read here from the raw TOML, not through the robot config), and `biped robots copy`
gives a pip-installed user a file to start from: named after the new file, never
overwriting, one line and exit 2 for every refusal."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from collections import Counter
from pathlib import Path

import pytest

import robot
import robot.cli as cli
from robot.config.robot_file import load_robot

#: The bundled robots as files: the package's own folder, listed here with os-level globbing.
ON_DISK = Path(robot.__file__).parent / "configs" / "robots"


@pytest.fixture(autouse=True)
def only_this_command(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cli, "COMMANDS", ("robots",))


def raw(name: str) -> dict:  # type: ignore[type-arg]
    return tomllib.loads((ON_DISK / f"{name}.toml").read_text())


def bundled() -> list[str]:
    return sorted(p.name.removesuffix(".toml") for p in ON_DISK.iterdir()
                  if p.name.endswith(".toml"))


def one_error_line(capsys: pytest.CaptureFixture[str]) -> str:
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1, captured.err
    return captured.err


def test_the_list_names_every_bundled_robot_with_its_bus_servos_and_joints(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert len(bundled()) >= 5
    assert cli.main(["robots"]) == 0
    lines = capsys.readouterr().out.splitlines()
    rows = {line.split()[0]: line for line in lines[1:] if line.split()[0] in bundled()}
    assert sorted(rows) == bundled()
    for name, line in rows.items():
        data = raw(name)
        models = Counter(j.get("model", data["bus"]["model"]) for j in data["joints"].values())
        assert line.split()[1] == data["bus"]["kind"], line
        for model, n in models.items():
            assert f"{n} x {model}" in line, line
        assert f" {len(data['joints'])}: legs 2 x " in line, line
    assert "biped robots copy NAME" in lines[-1]


def test_json_is_one_list_matching_the_files(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["robots", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in rows] == bundled()
    for r in rows:
        data = raw(r["name"])
        assert Path(r["file"]).read_text() == (ON_DISK / f"{r['name']}.toml").read_text()
        assert (r["bus"], r["baud"]) == (data["bus"]["kind"], data["bus"]["baud"])
        assert {j["name"]: j["servo_id"] for j in r["joints"]} == {
            n: t["servo_id"] for n, t in data["joints"].items()}
        assert sum(r["servos"].values()) == len(data["joints"])
        assert r["about"].endswith(".") and len(r["about"]) > 20


def test_copy_writes_the_file_named_after_it_and_never_overwrites(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dest = tmp_path / "my-biped.toml"
    assert cli.main(["robots", "copy", "biped18-feetech", str(dest)]) == 0
    assert f"wrote {dest}" in capsys.readouterr().out
    src = (ON_DISK / "biped18-feetech.toml").read_text().splitlines()
    new = dest.read_text().splitlines()
    assert [(a, b) for a, b in zip(src, new, strict=True) if a != b] == [
        ('name = "biped18-feetech"', 'name = "my-biped"')]             # comments and all
    copied = load_robot(dest)
    assert copied.name == "my-biped" and copied.joints == load_robot("biped18-feetech").joints
    dest.write_text(dest.read_text() + "# my notes\n")
    before = dest.read_text()
    assert cli.main(["robots", "copy", "biped18-dynamixel", str(dest)]) == 2
    assert "exists; not overwritten" in one_error_line(capsys)
    assert dest.read_text() == before


def test_copy_into_a_directory_keeps_the_name(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["robots", "copy", "biped18-lx", str(tmp_path)]) == 0
    assert load_robot(tmp_path / "biped18-lx.toml").name == "biped18-lx"
    capsys.readouterr()
    assert cli.main(["robots", "copy", "biped18-lx", str(tmp_path)]) == 2
    assert "exists" in one_error_line(capsys)


@pytest.mark.parametrize(("argv", "needle"), [
    (["copy", "biped99", "x.toml"], "copy NAME 'biped99': not a bundled robot; valid: "
                                    "biped12-legs, "),
    (["copy", "biped18-lx", "mine"], "expected a file name ending in .toml"),
    (["copy", "biped18-lx", "no/such/dir/x.toml"], "does not exist"),
    (["copy", "biped18-lx"], "the following arguments are required: DEST"),
    (["paste"], "invalid choice: 'paste'"),
])
def test_bad_copies_are_one_line_and_write_nothing(
        argv: list[str], needle: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(["robots", *argv]) == 2
    assert needle in one_error_line(capsys)
    assert list(tmp_path.iterdir()) == []


def test_copy_from_outside_the_checkout(tmp_path: Path) -> None:
    """The way a pip-installed user runs it: a fresh process in their own directory."""
    done = subprocess.run([sys.executable, "-m", "robot.cli", "robots", "copy",
                           "biped12-legs", "legs.toml"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert load_robot(tmp_path / "legs.toml").name == "legs"
