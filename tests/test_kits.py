"""The bundled kits are the importer's output: `biped robots import` on the published
models in ../shared/robots/ with the recipes in robot/configs/import/ writes exactly the
bundled robot files, so what is bundled is numbers the importer made from the vendor's
file, never a hand-edited copy. And each walks: `biped walk --robot K --seconds 30` in its
own model, balance on, stays up at a walking speed (the bundled robots' 0.10 m/s scaled
by leg length, tests/walk_criteria.py) and heading."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import robot.cli as cli
from robot.config.robot_file import load_robot

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "robots"
KITS = {"robotis-op3": SHARED / "robotis_op3" / "op3.xml",
        "open-duck-mini-v2": SHARED / "open_duck_mini_v2" / "robot.xml"}


@pytest.mark.parametrize("kit", sorted(KITS))
def test_the_bundled_kit_is_the_importers_output(kit: str, tmp_path: Path) -> None:
    out = tmp_path / f"{kit}.toml"
    recipe = REPO / "robot" / "configs" / "import" / f"{kit}.toml"
    assert cli.main(["robots", "import", str(KITS[kit]), "--missing-meshes", "box",
                     "--map", str(recipe), "--out", str(out)]) == 0
    bundled = REPO / "robot" / "configs" / "robots" / f"{kit}.toml"
    assert out.read_text() == bundled.read_text(), (
        f"robot/configs/robots/{kit}.toml is not what the import writes: run the command at "
        f"the top of {recipe.relative_to(REPO)}")


@pytest.mark.parametrize("kit", sorted(KITS))
def test_the_kit_walks_30s_with_balance(kit: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["walk", "--json", "--robot", kit, "--seconds", "30"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["balance"] is True and r["bus"] == "sim"
    assert r["fell"] is False and r["stop_reason"] == "completed", r["fell_at_s"]
    g = load_robot(kit).geometry
    assert r["speed_m_s"] >= 0.10 * (g.thigh + g.shin) / 0.22, r["speed_m_s"]
    assert abs(r["lateral_drift_m"]) <= 0.10 * r["distance_m"]
    assert abs(r["heading_change_deg"]) <= 10.0, r["heading_change_deg"]
