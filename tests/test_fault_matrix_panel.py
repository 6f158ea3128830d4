"""Fault matrix, the panel's part: the routes that move servos (start, record, limb
release) and the e-stop, sent at the same moment or a few milliseconds apart from their
own connections, as a script would, against `biped panel` on the pty emulator (the real
SDK), 10 repetitions each. Judged at the wire (the emulator's log and registers): one
owner at a time (no goals to a servo whose torque another request turned off, consecutive
goals within the slew limit), and after an e-stop answers no goal and no torque-on, torque
off on every servo. A request refused because another one owns the bus gets 409 naming it.
"""

from __future__ import annotations

import random
from collections.abc import Iterator
from pathlib import Path

import pytest
from bus_harness import TEST_TIMEOUT_MS, robot_for
from panel_wire import (
    MOVERS,
    Panel,
    Shot,
    assert_estop_held,
    assert_one_owner,
    fire,
    launched,
    settle,
    torque_now,
)
from test_fault_matrix import assert_stream_safe, goal_writes
from waiting import wait_for

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPS = 10
WHILE_GOALS = 60  # goal packets a run that won streams before the next repetition [ticks]
PROTOCOL = "dynamixel"  # the bus is irrelevant to who owns it; the other protocol is in
                        # test_panel_end_paths


def _shots(name: str, rep: int, rng: random.Random) -> list[Shot]:
    """The requests of one repetition of scenario ``name``."""
    within_30ms = rng.uniform(0.0, 0.03)
    return {
        "start_and_release_legs": [Shot("/api/start"),
                                   Shot("/api/pose/release", {"limb": "legs"})],
        "release_arms_then_estop": [Shot("/api/pose/release", {"limb": "arms"}),
                                    Shot("/api/estop", offset_s=within_30ms)],
        "start_then_estop_4ms": [Shot("/api/start"), Shot("/api/estop", offset_s=0.004)],
        "record_start_release_estop": [Shot("/api/record", {"name": f"r{rep}"}),
                                       Shot("/api/start"),
                                       Shot("/api/pose/release", {"limb": "legs"}),
                                       Shot("/api/estop", offset_s=within_30ms)],
    }[name]


@pytest.fixture(scope="module")
def chain() -> Iterator[tuple[Emulator, RobotConfig]]:
    robot = robot_for(PROTOCOL)
    with Emulator(PROTOCOL, robot, seed=1) as emu:
        yield emu, robot


@pytest.fixture(scope="module")
def served(chain: tuple[Emulator, RobotConfig], tmp_path_factory: pytest.TempPathFactory
           ) -> Iterator[Panel]:
    emu, _ = chain
    tmp = tmp_path_factory.mktemp("panel")
    text = (ROBOTS_DIR / f"biped18-{PROTOCOL}.toml").read_text()
    toml = tmp / "robot.toml"
    toml.write_text(text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}"))
    with launched(emu, toml, tmp) as panel:
        yield panel


SCENARIOS = ("start_and_release_legs", "release_arms_then_estop", "start_then_estop_4ms",
             "record_start_release_estop")


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_concurrent_routes_one_owner_estop_latched(
        chain: tuple[Emulator, RobotConfig], served: Panel, scenario: str,
        tmp_path: Path) -> None:
    emu, robot = chain
    rng = random.Random(scenario)
    for rep in range(REPS):
        settle(served)
        emu.log(clear=True)
        shots = fire(served, _shots(scenario, rep, rng))
        where = f"{scenario} #{rep}: " + ", ".join(
            f"{s.path} {s.status} {s.reply.get('error', s.reply.get('state', ''))}"
            for s in shots)
        movers = [s for s in shots if s.path in MOVERS]
        assert all(s.status in (200, 409) for s in shots), where
        for s in movers:
            if s.status == 409:  # names what holds the bus (or the e-stop that won)
                assert s.reply["error"].strip(), where
        estop = next((s for s in shots if s.path == "/api/estop"), None)
        if estop is not None:
            assert estop.status == 200 and estop.reply["state"] == "estop", where
            assert wait_for(lambda: not served.state()["running"]), where
            log = emu.log()
            assert_estop_held(robot, log, PROTOCOL, estop.sent)
            assert set(torque_now(emu, robot).values()) == {0}, where
        else:  # let the winner stream a while: a second loop would show in the goals
            assert wait_for(lambda: len(goal_writes(emu)) >= WHILE_GOALS
                            or not served.state()["running"]), where
            settle(served)
            log = emu.log()
        assert_one_owner(robot, log, PROTOCOL)
        goals = goal_writes(emu)
        if goals:
            assert_stream_safe(robot, goals)
