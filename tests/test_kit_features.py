"""Every sim feature on an imported robot: the bundled robotis-op3 (the ROBOTIS OP3's own
body, imported) goes through walk with balance, render, curves, export and import back,
a take replayed with the physics check, sim-gap, the tuner over the robustness suite's
flat walks (the suite's figures per kit are in docs/robustness.md) and `biped mjcf`,
each briefly; each must finish as it does on a box robot, and what it says
must be about this robot (its joints, its mass)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest

import robot.cli as cli
from robot.config.robot_file import load_robot

KIT = "robotis-op3"


def biped(*args: str, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "robot.cli", *args], capture_output=True,
                          text=True, timeout=timeout, check=False)


@pytest.fixture(scope="module")
def take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 3 s walk of the kit recorded as a take (with balance)."""
    path = tmp_path_factory.mktemp("kit") / "walk.take.jsonl"
    r = biped("walk", "--robot", KIT, "--seconds", "3", "--record", str(path), "--json")
    assert r.returncode == 0, r.stderr[-2000:]
    result = json.loads(r.stdout)
    assert not result["fell"] and result["distance_m"] > 0.1, result
    return path


def test_render_draws_the_kit(tmp_path: Path) -> None:
    out = tmp_path / "k.gif"
    assert cli.main(["render", "--robot", KIT, "--seconds", "0.2", "--out", str(out)]) == 0
    assert out.stat().st_size > 1000


def test_curves_and_export_import_round_trip(tmp_path: Path) -> None:
    csv = tmp_path / "c.csv"
    assert cli.main(["curves", "--robot", KIT, "--seconds", "1", "--out", str(csv)]) == 0
    header = csv.read_text().splitlines()[0].split(",")
    assert {f"q_{j}" for j in load_robot(KIT).joint_names} <= set(header)
    bvh, back = tmp_path / "k.bvh", tmp_path / "k.take.jsonl"
    assert cli.main(["export", "--robot", KIT, "--seconds", "2", "--out", str(bvh)]) == 0
    assert cli.main(["import", str(bvh), "--robot", KIT, "--out", str(back)]) == 0
    assert back.stat().st_size > 1000


def test_play_checks_the_take_in_physics_and_sim_gap_compares_it(take: Path) -> None:
    r = biped("play", str(take), "--json")
    assert r.returncode == 0, r.stderr[-2000:]
    g = biped("sim-gap", str(take), "--json")
    assert g.returncode == 0, g.stderr[-2000:]
    gap = json.loads(g.stdout)
    assert set(load_robot(KIT).joint_names) <= set(json.dumps(gap).replace('"', " ").split())


def test_the_tuner_runs_the_robustness_suite_on_the_kit(tmp_path: Path) -> None:
    skip = [a for g in ("slope", "cross slope", "bumps", "push*", "latency", "imu noise")
            for a in ("--skip", g)]
    out = tmp_path / "t.toml"
    t = biped("tune", "--robot", KIT, "--out", str(out), "--param", "sway", "--seconds", "2",
              "--trials", "2", "--jobs", "1", *skip, "--json")
    assert t.returncode == 0, t.stderr[-2000:]
    assert json.loads(t.stdout)["trials"] >= 2 and out.exists()


def test_mjcf_is_what_is_simulated(tmp_path: Path) -> None:
    assert cli.main(["mjcf", "--robot", KIT, "--out", str(tmp_path)]) == 0
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "scene.xml"))
    body = load_robot(KIT).body
    assert body is not None
    assert model.body_subtreemass[model.body("torso").id] == pytest.approx(body.tree.mass)
