"""An import's recipe (`biped robots import --map`): which way the knees bend (said, or
found from the limits), the robot's own [gait], [balance] and per-joint gains carried into
the robot file, and every fault in it one line, exit 2, nothing written.

Oracles: the Open Duck Mini's own runtime (apirrone/Open_Duck_Mini_Runtime, HWI.init_pos:
right hip pitch +0.635, knee -1.379 in the project's terms once signed, inside the model's
ranges only with the knee bent backward), and the numbers written into the recipes here."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine

REPO = Path(__file__).resolve().parents[1]
DUCK = REPO.parent / "shared" / "robots" / "open_duck_mini_v2" / "robot.xml"
BASE = 'source = "test"\n[bus]\nkind = "feetech"\nmodel = "STS3215"\n' \
       '[joints.left_antenna]\nweld = true\n[joints.right_antenna]\nweld = true\n'


def run_import(tmp_path: Path, recipe: str) -> tuple[int, Path]:
    """`biped robots import` of the Duck with ``recipe`` as --map: (exit code, --out)."""
    rec = tmp_path / "recipe.toml"
    rec.write_text(recipe)
    out = tmp_path / "duck.toml"
    return cli.main(["robots", "import", str(DUCK), "--missing-meshes", "box", "--map",
                     str(rec), "--out", str(out)]), out


@pytest.mark.parametrize("knee", ["", 'knee = "back"\n'])
def test_the_ducks_knees_bend_backward_and_its_crouch_fits_its_limits(
        knee: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = run_import(tmp_path, knee + BASE)
    assert rc == 0
    summary = capsys.readouterr().out
    assert ("knees bend backward (--map)" if knee else
            "knees bend backward: the leg limits") in summary
    robot = load_robot(out)
    assert all(leg.knee_back for leg in robot.legs)
    assert robot.rest["r_knee"] == -1.1 and robot.rest["r_hip_pitch"] == 0.55
    # The runtime's init pose is inside the limits the model gives, knee bent backward.
    lim = {j.name: (j.min_rad, j.max_rad) for j in robot.joints}
    for name, q in (("r_hip_pitch", 0.635), ("r_knee", -1.379), ("r_ankle_pitch", 0.796)):
        assert lim[name][0] < q < lim[name][1], name
    # The gait's standing crouch bends the knees backward, off every limit.
    q = dict(zip(robot.joint_names, GaitEngine(robot, load_gait("walk").for_robot(robot))
                 .start_pose(), strict=True))
    for side in "rl":
        assert q[f"{side}_knee"] < -0.5 and q[f"{side}_hip_pitch"] > 0.2
        for part in ("hip_pitch", "knee", "ankle_pitch"):
            lo, hi = lim[f"{side}_{part}"]
            assert lo + 0.05 < q[f"{side}_{part}"] < hi - 0.05, (side, part)


def test_said_forward_the_crouch_pins_the_hip_at_its_limit(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = run_import(tmp_path, 'knee = "forward"\n' + BASE)
    assert rc == 0
    assert "knees bend forward (--map)" in capsys.readouterr().out
    robot = load_robot(out)
    assert not any(leg.knee_back for leg in robot.legs)
    assert robot.rest["r_hip_pitch"] == robot.joint("r_hip_pitch").min_rad   # clamped


def test_the_recipes_gait_balance_and_joint_gains_reach_the_robot_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = run_import(tmp_path, BASE + "[gait]\nvM = 0.55\nWpos_R = 0.1\n[balance]\n"
                         "bal_hold_xi = 0.03\n[joints.right_knee]\n"
                         "gains = { p_coefficient = 40, d_coefficient = 12 }\n")
    assert rc == 0
    robot = load_robot(out)
    assert robot.gait == {"vM": 0.55, "Apos_R": 0.1}
    assert robot.balance == {"bal_hold_xi": 0.03}
    assert dict(robot.joint("r_knee").gains) == {"p_coefficient": 40, "d_coefficient": 12}
    assert dict(robot.joint("l_knee").gains) == {}
    data = tomllib.loads(out.read_text())
    assert data["joints"]["r_knee"]["gains"]["p_coefficient"] == 40


@pytest.mark.parametrize(("extra", "want"), [
    ('knee = "sideways"\n', "knee: 'sideways'; valid: forward, back"),
    ("[gait]\nturn = 0.1\n", "gait.turn: not a gait parameter of the robot"),
    ("[gait]\nbal_hold_xi = 0.1\n", "a balance gain belongs in [balance]"),
    ("[joints.right_knee]\ngains = 3\n", "joints.right_knee.gains: expected a table"),
    ("[joints.right_knee]\ngains = { p_coefficient = 999 }\n",
     "(from --map"),
])
def test_a_bad_recipe_is_one_line_and_nothing_written(
        extra: str, want: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = run_import(tmp_path, extra + BASE if extra.startswith("knee") else BASE + extra)
    assert rc == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and want in err, err
    assert not out.exists()
