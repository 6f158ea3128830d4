"""Fault matrix: every way a `biped walk` can end, on the pty emulator with the real vendor
SDKs (both protocols), with and without --hold. The verdict is the end state read back
from the emulated servos' registers (torque per servo, last goal), the exit code and the
one-line cause, plus the whole goal stream: never outside the joint limits, never faster
than the slew limit.

Expected tick limits and slew steps are computed here from the robot file by hand (the
manual's tick formula), not by ``ServoMap``.

This file: bus faults. A jam mid-walk, hardware error flags, a full disk and a closed port
are tests/test_fault_matrix_ends.py, signals tests/test_fault_matrix_signals.py; the
oracles and the runner tests/fault_matrix.py (three files run side by side).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from fault_matrix import (
    INJECT_AFTER_GOALS,
    UNHELD,
    VICTIM,
    assert_stream_safe,
    goal_writes,
    inject_when_streaming,
    last_goals,
    rest_ticks,
    run_walk,
    torque,
    victim_id,
    walk_args,
)

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


# ------------------------------------------------------------------------------ cases
@dataclass(frozen=True)
class Fault:
    """name; inject(emu, robot) or None; the end it must reach: "ok" (exit 0, rest, torque
    as --hold says), "ramp" (exit 1, ramped to rest, torque off), "off" (exit 1, torque off
    at once: goals stop soon after the fault), "either" (ok or off: a noisy bus that may or
    may not reach the error streak); cause: text the one-line stop reason must contain;
    after: goal packets before the fault is injected."""

    name: str
    inject: Callable[[Emulator, RobotConfig], None] | None
    end: str
    cause: str = ""
    after: int = INJECT_AFTER_GOALS


FAULTS = [
    Fault("none", None, "ok", "completed"),
    Fault("drop10", lambda e, r: e.set_faults(drop_rate=0.1), "either"),
    Fault("drop50", lambda e, r: e.set_faults(drop_rate=0.5), "either"),
    Fault("drop100", lambda e, r: e.set_faults(drop_rate=1.0), "off", "bus errors"),
    Fault("corrupt30", lambda e, r: e.set_faults(corrupt_rate=0.3), "either"),
    Fault("corrupt100", lambda e, r: e.set_faults(corrupt_rate=1.0), "off", "bus errors"),
    Fault("vanish", lambda e, r: e.set_faults(vanish={victim_id(r): 0.0}), "off", "bus errors"),
    # Jammed from the first goal: the ramp-in bends the knee ~1 rad; it stays straight.
    Fault("stuck", lambda e, r: e.set_faults(stuck_ids=[victim_id(r)]), "off",
          f"servo {{}} ({VICTIM}) stopped following", after=1),
]


@pytest.mark.parametrize("hold", [False, True], ids=["nohold", "hold"])
@pytest.mark.parametrize("fault", FAULTS, ids=[f.name for f in FAULTS])
def test_bus_faults(emu: Emulator, robot: RobotConfig, robot_toml: Path, fault: Fault,
                    hold: bool, capsys: pytest.CaptureFixture[str]) -> None:
    action = (lambda: fault.inject(emu, robot)) if fault.inject else None
    t0 = time.monotonic()
    with inject_when_streaming(emu, action, after=fault.after) as info:
        code, result, err = run_walk(walk_args(emu, robot_toml, hold=hold), capsys)
    emu.clear_faults()
    reason = result["stop_reason"]
    cause = fault.cause.format(victim_id(robot))
    assert "\n" not in reason
    goals = goal_writes(emu)
    assert_stream_safe(robot, goals)
    assert time.monotonic() - t0 < 25
    reachable = tuple(i for i in robot.ids if fault.name != "vanish" or i != victim_id(robot))
    end = fault.end
    if end == "either":   # a noisy bus: it completes, stops, or completes but cannot hold
        end = ("ok" if code == 0 else
               "unheld" if reason.startswith(UNHELD) else "off")
    if end == "unheld":   # ramped out to rest; the last read failed: no hold, torque off
        assert code == 1 and hold and result["fault"] and not result["holding"], err
        assert last_goals(emu, robot) == rest_ticks(robot)
        assert torque(emu, robot.ids) == {0}
    elif end == "ok":
        assert code == 0, err
        assert reason == "completed"
        assert last_goals(emu, robot) == rest_ticks(robot)
        assert torque(emu, robot.ids) == {1 if hold else 0}
        assert result["holding"] is hold
    else:
        assert code == 1, err
        assert result["fault"] and not result["holding"]
        assert cause in reason and reason.startswith("watchdog")
        assert torque(emu, reachable) == {0}                 # hold or not
        assert info["at"] is not None
        stopped = max(p.t for p in goals) - info["at"]
        assert stopped < 3.0                                  # no ramp-out: stopped at once
