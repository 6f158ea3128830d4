"""Benchmark of the simulated walk (`biped bench --only sim`): how much faster than real
time one process walks, open loop and with balance (IMU + feedback), and which share of
the time MuJoCo's own stepping takes (its timers) versus everything else in the loop.

Each configuration runs ``repeats`` times; reported as the median and the spread of the
realtime factor (sim seconds / wall seconds of the loop) and the physics share. Machines
are shared: compare ratios measured in one run, never absolute numbers across machines.

``presets``: every bundled gait preset walked for 60 s on the flat on every bundled robot
(5 s with ``quick``), as `biped walk` runs it (balance on where the robot has an IMU):
whether it fell, its speed and heading change, its heading drift per minute and its speed
against its own (``planned_speed``); ``flags`` says which walking preset turns more than
DRIFT_DEG_MIN per minute or walks under WALK_SHARE of its speed, and why. The simulated
servos are the identified ones at the robot file's gains (docs/servos.md), so this is
where a gain choice that makes a preset sag or fall shows. ``stops``: the stop study
(robot.bench.stops).
"""

from __future__ import annotations

import statistics
import time
from typing import Any

from robot.balance.stage import Balance, attitude_reader
from robot.bench.stops import run_stops
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import gait_names, made_for, robot_names
from robot.config.gait_file import load_gait
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.imu import open_imu
from robot.loop.streamer import Streamer
from robot.previs.travel import Efficiency, unit_travel


def _walk(robot_name: str, seconds: float, *, balance: bool) -> tuple[float, float]:
    """(realtime factor, share of the loop's wall time spent in mj_step)."""
    import mujoco

    robot = load_robot(robot_name)
    bus: Any = make_bus("sim", robot=robot)
    with bus:
        engine = GaitEngine(robot, load_gait("walk").for_robot(robot))
        feedback = None
        imu = None
        if balance and robot.imu is not None:
            imu = open_imu(robot.imu, bus=bus)
            imu.open()
            feedback = Balance(engine, attitude_reader(imu))
        streamer = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0, feedback=feedback)
        t0 = time.perf_counter()
        stats = streamer.run(seconds=seconds)
        wall = time.perf_counter() - t0
        physics = float(bus.data.timer[mujoco.mjtTimer.mjTIMER_STEP].duration)
        if imu is not None:
            imu.close()
    return stats.duration_s / wall, physics / wall


def planned_speed(robot: RobotConfig, params: GaitParams) -> float:
    """The preset's own speed on ``robot`` [m/s]: its stance foot's travel under the pelvis
    per second (2 x stride amplitude per step, robot.previs.travel.unit_travel, with no
    slip) x ``speed``."""
    return unit_travel(robot, params, Efficiency(forward=1.0))[0] * params.speed


def _preset(robot_name: str, gait_name: str, seconds: float) -> dict[str, Any]:
    from robot.run.run import execute
    from robot.run.spec import RunOptions
    from robot.run.walk import walk_imu, walk_spec, walk_summary

    robot = load_robot(robot_name)
    gait = load_gait(gait_name)
    params = gait.for_robot(robot)
    bus: Any = make_bus("sim", robot=robot)
    spec = walk_spec(robot, params, bus, gait=gait_name,
                     imu=walk_imu(robot, bus), options=RunOptions(seconds=seconds))
    r = walk_summary(spec, execute(spec), gait=gait_name)
    planned = planned_speed(robot, params)
    return {"fell": r["fell"], "fell_at_s": r["fell_at_s"],
            "speed_m_s": round(r["speed_m_s"], 3),
            "heading_change_deg": round(r["heading_change_deg"], 1),
            "heading_drift_deg_min": round(r.get("heading_drift_deg_min", 0.0), 1),
            "planned_speed_m_s": round(planned, 3),
            "speed_share": round(r["speed_m_s"] / planned, 2) if abs(planned) > 1e-9 else None,
            "ik_unreachable_s": round(r["ik_unreachable_s"], 1),
            "clamped_joints_s": {k: round(v, 1) for k, v in r["clamped_joints_s"].items()
                                 if v >= 1.0},
            "braced_s": round(r["braced_s"], 1)}


#: A walking preset holds its heading within this [deg per minute] beyond what it asks,
#: and walks at least WALK_SHARE of its own speed (``planned_speed``) on the robot; a
#: preset that marches in place stays within IN_PLACE_M_S of its start (issue 32 item 4).
DRIFT_DEG_MIN = 10.0
WALK_SHARE = 0.5
IN_PLACE = frozenset({"march"})
IN_PLACE_M_S = 0.005


def flags(row: dict[str, Any], gait: str) -> list[str]:
    """What is wrong with a 60 s walk of ``gait`` (a ``_preset`` row), each with the
    figures that say why; empty: it walked straight at its speed."""
    out = []
    if row["fell"]:
        return [f"fell at {row['fell_at_s']:.1f} s"]
    drift = row["heading_drift_deg_min"]
    if abs(drift) > DRIFT_DEG_MIN:
        out.append(f"turns {drift:+.1f} deg/min unasked (over {DRIFT_DEG_MIN:g})")
    v, planned = row["speed_m_s"], row["planned_speed_m_s"]
    if gait in IN_PLACE:
        if abs(v) > IN_PLACE_M_S:
            out.append(f"marches off the spot at {v:+.3f} m/s (in place: within "
                       f"{IN_PLACE_M_S:g})")
    elif v < WALK_SHARE * planned:
        out.append(f"walks {v:.3f} m/s, {100 * v / planned:.0f} % of its {planned:.3f} m/s "
                   f"(under {100 * WALK_SHARE:.0f} %)")
    if out:      # what the walk's summary says of the cause
        why = [f"{k} at its limit {t:.0f} s" for k, t in row["clamped_joints_s"].items()]
        if row["ik_unreachable_s"] >= 1.0:
            why.append(f"IK out of reach {row['ik_unreachable_s']:.0f} s")
        if row["braced_s"] >= 1.0:
            why.append(f"braced {row['braced_s']:.0f} s")
        if why:
            out.append("; ".join(why))
    return out


#: Presets for previs only, not for a robot to walk (their files say so: "paper" is the
#: paper's equations verbatim, with no weight shift): walked and reported, not counted.
PREVIS_ONLY = frozenset({"paper", "run"})
#: Presets planned for a world the flat is not: walked and reported, not counted. `climb`
#: plans footsteps for the staircase its `stairs_*` parameters describe (3 x 1.5 cm), and
#: on the flat the steps it shortens and closes for risers that are not there tip the
#: 12-joint robot over 7.4 s in (docs/gait.md, "climb").
NEEDS_ITS_WORLD = frozenset({"climb"})


def run_presets(*, quick: bool = False) -> dict[str, Any]:
    """Every bundled preset on every bundled robot: 60 s on the flat (5 s quick);
    ``all_walked``: no preset meant for a robot fell; ``all_straight``: none meant for a
    robot has ``flags`` (judged on 60 s walks only: a 5 s heading says little of a
    minute's)."""
    seconds = 5.0 if quick else 60.0
    out: dict[str, Any] = {"seconds": seconds}
    walked = straight = True
    for robot in robot_names():
        for gait in gait_names():
            row = out[f"{robot} {gait}"] = _preset(robot, gait, seconds)
            counted = not (gait in PREVIS_ONLY or gait in NEEDS_ITS_WORLD
                           or not made_for(robot, gait))
            walked = walked and (not counted or not row["fell"])
            if counted and not quick:
                row["flags"] = flags(row, gait)
                straight = straight and not row["flags"]
    out["all_walked"] = walked
    out["all_straight"] = None if quick else straight
    return out


def run_sim_bench(*, quick: bool = False) -> dict[str, Any]:
    seconds, repeats = (1.0, 1) if quick else (20.0, 5)
    out: dict[str, Any] = {"walk_seconds": seconds, "repeats": repeats}
    # the box models, and the imported kits (their own bodies: hull and box collisions)
    for robot in ("biped18-dynamixel", "biped18-feetech", "robotis-op3", "open-duck-mini-v2"):
        for balance in (False, True):
            runs = [_walk(robot, seconds, balance=balance) for _ in range(repeats)]
            factors = sorted(r[0] for r in runs)
            out[f"{robot} {'balance' if balance else 'open loop'}"] = {
                "realtime_factor_median": round(statistics.median(factors), 2),
                "realtime_factor_min_max": [round(factors[0], 2), round(factors[-1], 2)],
                "mj_step_share_of_loop": round(statistics.median(r[1] for r in runs), 3),
            }
    out["presets"] = run_presets(quick=quick)
    out["stops"] = run_stops(quick=quick)
    return out
