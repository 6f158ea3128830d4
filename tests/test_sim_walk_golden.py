"""The simulated walk, bit for bit, against one stored before the sim loop was sped up.

Each robot of `biped bench --only sim` (the two box models and the two imported kits)
walks the ``walk`` preset (with the robot's own ``[gait]``) for 10 s on the sim bus, open
loop and with balance (the sim IMU and robot.balance), exactly as the bench runs it
(robot.bench.sim); the final state of the physics (qpos, qvel, sim time) and the last
commanded joint angles are compared bit for bit with tests/data/sim_walk_golden.json. A 10
s walk is chaotic enough that any change to what is computed (an operation reordered, a
contact dropped or added, one step more or less) shows in the last bits of qpos, so this
is the check that a speed-up of the loop changed no result.

The fixture was written by ``python tests/test_sim_walk_golden.py --write`` from main's
code before the change (run with main's tree first on PYTHONPATH). Bit-for-bit equality is
a property of one platform (MuJoCo's build, numpy, libm, the CPU): the fixture records
where it was made and a mismatch says so.
"""

from __future__ import annotations

import json
import platform
import sys
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from robot.balance.stage import Balance, attitude_reader
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.imu import open_imu
from robot.loop.streamer import Streamer

FIXTURE = Path(__file__).parent / "data" / "sim_walk_golden.json"
ROBOTS = ("biped18-dynamixel", "biped18-feetech", "robotis-op3", "open-duck-mini-v2")
SECONDS = 10.0


def fingerprint() -> str:
    """Where the last bits come from: MuJoCo, numpy, the platform and libc."""
    return (f"mujoco {mujoco.__version__}; numpy {np.__version__}; {platform.machine()} "
            f"{' '.join(platform.libc_ver())}")


def hexes(a: Any) -> list[str]:
    return [float(x).hex() for x in np.asarray(a, dtype=float).ravel()]


def walk(robot_name: str, *, balance: bool) -> dict[str, Any]:
    """A 10 s walk as robot.bench.sim runs it; its final state, floats as hex."""
    robot = load_robot(robot_name)
    bus: Any = make_bus("sim", robot=robot)
    with bus:
        engine = GaitEngine(robot, load_gait("walk").for_robot(robot))
        feedback = imu = None
        if balance:
            assert robot.imu is not None
            imu = open_imu(robot.imu, bus=bus)
            imu.open()
            feedback = Balance(engine, attitude_reader(imu))
        streamer = Streamer(ServoMap(robot), bus, engine, rate_hz=200.0, feedback=feedback)
        stats = streamer.run(seconds=SECONDS)
        d = bus.data
        out = {"time": float(d.time).hex(), "ticks": stats.ticks, "qpos": hexes(d.qpos),
               "qvel": hexes(d.qvel), "q_cmd": hexes(streamer.telemetry.q_cmd)}
        if imu is not None:
            imu.close()
    return out


CONFIGS = [(r, b) for r in ROBOTS for b in (False, True)]


def key(robot: str, balance: bool) -> str:
    return f"{robot} {'balance' if balance else 'open loop'}"


@pytest.fixture(scope="module")
def golden() -> dict[str, Any]:
    stored: dict[str, Any] = json.loads(FIXTURE.read_text())
    return stored


@pytest.mark.parametrize(("robot", "balance"), CONFIGS, ids=[key(*c) for c in CONFIGS])
def test_a_10_s_sim_walk_ends_bit_for_bit_where_it_did(
        robot: str, balance: bool, golden: dict[str, Any]) -> None:
    want = golden["walks"][key(robot, balance)]
    got = walk(robot, balance=balance)
    where = f"{key(robot, balance)} (fixture made on {golden['fingerprint']}; " \
            f"this is {fingerprint()})"
    assert got["ticks"] == want["ticks"], where
    assert got["time"] == want["time"], where
    for field in ("q_cmd", "qpos", "qvel"):
        a = np.array([float.fromhex(x) for x in got[field]])
        b = np.array([float.fromhex(x) for x in want[field]])
        assert a.shape == b.shape, f"{where}: {field} has {a.size} values, stored {b.size}"
        if got[field] != want[field]:
            i = int(np.flatnonzero(a != b)[0])
            pytest.fail(f"{where}: {field}[{i}] = {a[i]!r}, stored {b[i]!r} "
                        f"(max |diff| {np.max(np.abs(a - b)):.3g})")


def test_the_stored_walks_are_whole_walks() -> None:
    """The fixture is of whole walks: each ran its 10 s of gait, and each balanced one
    kept its pelvis up (above 0.1 m; open loop the Duck sinks to 0.10 m by the end)."""
    stored = json.loads(FIXTURE.read_text())["walks"]
    for k, w in stored.items():
        assert float.fromhex(w["time"]) > SECONDS, k
        if k.endswith(" balance"):
            assert float.fromhex(w["qpos"][2]) > 0.1, (k, w["qpos"][2])


def write_fixture() -> None:
    out = {"fingerprint": fingerprint(), "seconds": SECONDS,
           "walks": {key(r, b): walk(r, balance=b) for r, b in CONFIGS}}
    tmp = FIXTURE.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(FIXTURE)


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        sys.exit("usage: python tests/test_sim_walk_golden.py --write  (rewrites the fixture "
                 "from the code as it is now)")
    write_fixture()
