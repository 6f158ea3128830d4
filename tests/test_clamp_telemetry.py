"""The loop's per-tick telemetry names each joint held at a limit (``Telemetry.clamped``),
whether the gait engine held it (its IK asked beyond the limit) or the loop did (a feedback
correction beyond it), and the panel's snapshot and ``--record`` carry it.

Oracles: the general functions' unclamped angles against the robot file's limits (the
engine's own kernel not consulted), and a feedback stage that pushes one joint a known
amount past its limit."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from robot.bus.servo_map import ServoMap
from robot.cli import main
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.engine import GaitEngine
from robot.gait.targets import body_targets
from robot.gait.vectorised import solve
from robot.loop.source import JointVector
from robot.loop.streamer import Streamer, Telemetry
from robot.panel.snapshot import telemetry_snapshot
from sim.mujoco.bus import MujocoBus

DXL = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
HIGH_ARMS = {"Ahgt_R": 2.0, "Ahgt_L": 2.0,   # hands raised beyond the shoulders' reach,
             "ramp_cycles": 0.5}               # at full amplitude within 0.44 s


def _stream(engine: GaitEngine, seconds: float, feedback: object = None
            ) -> list[tuple[str, tuple[str, ...], set[str]]]:
    """(state, tel.clamped, the joints the general functions put beyond a limit) per tick."""
    bus = MujocoBus(DXL)
    bus.open()
    seen: list[tuple[str, tuple[str, ...], set[str]]] = []

    def observe(tel: Telemetry) -> None:
        beyond: set[str] = set()
        if tel.state in ("walking", "ramp_out"):
            p, a = engine.live_params, engine.amplitude
            raw, _ = solve(body_targets(gait.channels(engine.phase, p, amplitude=a), p,
                                        DXL.geometry, amplitude=a), DXL)
            beyond = {j.name for v, j in zip(raw, DXL.joints, strict=True)
                      if not j.min_rad <= float(v) <= j.max_rad}
        seen.append((tel.state, tel.clamped, beyond))
        assert telemetry_snapshot(tel)["clamped"] == list(tel.clamped)
    try:
        Streamer(ServoMap(DXL), bus, engine, observer=observe,
                 feedback=feedback).run(seconds=seconds)  # type: ignore[arg-type]
    finally:
        bus.close()
    return seen


def test_telemetry_names_the_joints_the_gait_held_at_a_limit() -> None:
    engine = GaitEngine(DXL, load_gait("walk").params.replace(HIGH_ARMS))
    seen = _stream(engine, 1.0)
    gait_ticks = [(c, b) for s, c, b in seen if s in ("walking", "ramp_out")]
    assert len(gait_ticks) >= 150
    assert all(set(c) == b for c, b in gait_ticks)
    assert sum(1 for c, _ in gait_ticks if {"r_shoulder_pitch", "l_shoulder_pitch"} & set(c)) > 20
    assert any(not c for c, _ in gait_ticks)                  # the ramp-in's first ticks
    assert all(not c for s, c, _ in seen if s not in ("walking", "ramp_out"))
    names = list(DXL.joint_names)
    assert all(list(c) == sorted(c, key=names.index) for _, c, _ in seen)   # joint order


class _PastTheKnee:
    """A feedback stage that asks the right knee for 0.1 rad beyond its upper limit."""

    def __init__(self) -> None:
        self._knee = DXL.joint_names.index("r_knee")

    def start(self) -> None: ...

    def stop(self) -> None: ...

    def __call__(self, q: JointVector, dt: float) -> JointVector:
        out = q.copy()
        out[self._knee] = DXL.joint("r_knee").max_rad + 0.1
        return out


def test_telemetry_names_a_joint_the_loop_held_at_a_limit() -> None:
    seen = _stream(GaitEngine(DXL, load_gait("walk").params), 0.3, _PastTheKnee())
    gait_ticks = [c for s, c, _ in seen if s in ("walking", "ramp_out")]
    assert gait_ticks and all(c == ("r_knee",) for c in gait_ticks)


def test_the_record_has_a_clamped_column(tmp_path: Path) -> None:
    out = tmp_path / "run.csv"
    sets = [a for k, v in HIGH_ARMS.items() for a in ("--set", f"{k}={v}")]
    assert main(["walk", "--seconds", "1", "--no-balance", "--record", str(out), *sets]) == 0
    with out.open() as f:
        rows = list(csv.DictReader(f))
    held = [set(r["clamped"].split()) for r in rows if r["state"] == "walking"]
    assert held and np.mean([bool(h & {"r_shoulder_pitch", "l_shoulder_pitch"})
                             for h in held]) > 0.1
    assert all(r["clamped"] == "" for r in rows if r["state"] == "rest")
