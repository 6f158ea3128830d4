"""Run other people's servo libraries against `biped emulate` (issue 21; docs/third_party.md).

Each library is driven through its own calibration, velocity-mode and STS-centring
features; what it reads back is compared with what a real servo answers (the manuals'
relations, written here). Not a project test: these libraries are no dependency of the
project. Run it from a scratch venv that has them, pointing at the project's `biped`:

    python3 -m venv /tmp/3p && /tmp/3p/bin/pip install pypot rustypot pyax12 st3215 \
        feetech-cli dynamixel-sdk feetech-servo-sdk deepdiff tqdm
    /tmp/3p/bin/pip install --no-deps lerobot          # its motors package only
    /tmp/3p/bin/python docs/third_party_check.py --biped .venv/bin/biped [--json out.json]

LeRobot's ``lerobot.motors`` imports ``lerobot.utils.utils``, which imports torch,
accelerate and datasets for things the motor buses never call; the script puts empty
modules in their place rather than install a deep-learning stack to talk to a servo.
Prints one line per check (library, feature, ok/FAIL, what was seen); exit 1 if any failed.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import subprocess
import sys
import time
import traceback
import types
from collections.abc import Callable, Iterator
from typing import Any

BAUD = 1_000_000
ROBOTS = {"feetech": "biped18-feetech", "dynamixel": "biped18-dynamixel",
          "dynamixel1": "biped18-ax12"}
RESULTS: list[dict[str, str]] = []


@contextlib.contextmanager
def emulated(biped: str, protocol: str) -> Iterator[str]:
    """`biped emulate` serving the bundled robot of ``protocol``; yields the pty path."""
    proc = subprocess.Popen([biped, "emulate", "--robot", ROBOTS[protocol]],
                            stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        yield proc.stdout.readline().strip()
    finally:
        proc.terminate()
        proc.wait(10)


def check(library: str, feature: str, fn: Callable[[], str]) -> None:
    try:
        seen, ok = fn(), True
    except Exception as e:  # noqa: BLE001 - every failure is a finding
        where = traceback.extract_tb(e.__traceback__)[-1]
        seen, ok = f"{type(e).__name__}: {e} ({where.filename.split('/')[-1]}:{where.lineno})", \
            False
    RESULTS.append({"library": library, "feature": feature, "ok": str(ok), "seen": seen})
    print(f"{library:18s} {feature:34s} {'ok  ' if ok else 'FAIL'} {seen}", flush=True)


def expect(cond: bool, what: str) -> None:
    if not cond:
        raise AssertionError(what)


def wait(pred: Callable[[], bool], timeout: float = 10.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.02)
    return pred()


def sm(raw: int, bit: int) -> int:
    """Feetech sign-magnitude -> int."""
    return -(raw & ((1 << bit) - 1)) if raw >> bit & 1 else raw & ((1 << bit) - 1)


# ------------------------------------------------------------------ LeRobot
class _Absent(types.ModuleType):
    """A module the motor buses never use: any attribute is a placeholder class."""

    def __getattr__(self, name: str) -> Any:
        return type(name, (), {})


def shim_lerobot_imports() -> None:
    for name in ("torch", "accelerate", "datasets", "datasets.utils"):
        sys.modules.setdefault(name, _Absent(name))
    logging_mod = types.ModuleType("datasets.utils.logging")
    logging_mod.disable_progress_bar = lambda: None  # type: ignore[attr-defined]
    logging_mod.enable_progress_bar = lambda: None  # type: ignore[attr-defined]
    sys.modules.setdefault("datasets.utils.logging", logging_mod)


def lerobot_bus(kind: str, port: str) -> Any:
    shim_lerobot_imports()
    from lerobot.motors import Motor, MotorNormMode
    motors = {"j1": Motor(1, "sts3215" if kind == "feetech" else "xl430-w250",
                          MotorNormMode.RANGE_M100_100)}
    if kind == "feetech":
        from lerobot.motors.feetech import FeetechMotorsBus
        bus: Any = FeetechMotorsBus(port, motors)
    else:
        from lerobot.motors.dynamixel import DynamixelMotorsBus
        bus = DynamixelMotorsBus(port, motors)
    bus.connect()
    return bus


def lerobot(kind: str, port: str) -> None:
    name = f"lerobot {kind}"
    bus = lerobot_bus(kind, port)

    def configure() -> str:
        bus.configure_motors()
        if kind == "feetech":
            got = bus.read("Maximum_Acceleration", "j1", normalize=False)
            expect(got == 254, f"Maximum_Acceleration read {got}, wrote 254")
            return "Maximum_Acceleration(85) reads back 254"
        return f"Return_Delay_Time {bus.read('Return_Delay_Time', 'j1', normalize=False)}"

    def calibrate() -> str:
        bus.disable_torque()
        bus.reset_calibration()
        bus.enable_torque()                          # turn the joint off centre first
        bus.write("Goal_Position", "j1", 2300, normalize=False)
        wait(lambda: bus.read("Present_Position", "j1", normalize=False) == 2300)
        bus.disable_torque()
        raw = bus.read("Present_Position", "j1", normalize=False)
        homings = bus.set_half_turn_homings()
        now = bus.read("Present_Position", "j1", normalize=False)
        expect(now == 2047, f"after set_half_turn_homings present reads {now}, not 2047")
        cal = bus.read_calibration()["j1"]
        cal.range_min, cal.range_max = 2047 - 500, 2047 + 500
        bus.write_calibration({"j1": cal})
        middle = bus.read("Present_Position", "j1")   # normalized to -100..100
        expect(abs(middle) < 0.5, f"normalized position {middle} at the range's middle")
        return (f"present {raw} -> 2047 with Homing_Offset {homings['j1']}; "
                f"range 1547..2547 written, normalized {middle:+.1f}")

    def velocity() -> str:
        mode = 1                                     # both: 1 = velocity / constant speed
        bus.disable_torque()
        bus.write("Operating_Mode", "j1", mode)
        bus.enable_torque()
        bus.write("Goal_Velocity", "j1", 200)          # XL430 Velocity Limit(44): 265
        got = bus.read("Present_Velocity", "j1", normalize=False)
        start = bus.read("Present_Position", "j1", normalize=False)
        moved = wait(lambda: bus.read("Present_Position", "j1", normalize=False) != start)
        bus.write("Goal_Velocity", "j1", 0)
        bus.disable_torque()
        bus.write("Operating_Mode", "j1", 0 if kind == "feetech" else 3)
        expect(got == 200 and moved, f"Present_Velocity {got}, moved {moved}")
        return "Goal_Velocity 200 -> Present_Velocity 200, position turning"

    check(name, "configure_motors", configure)
    check(name, "calibration (half-turn homings)", calibrate)
    check(name, "velocity mode", velocity)
    bus.disconnect()


# ------------------------------------------------------------------ feetech-cli, st3215
def feetech_cli(port: str) -> None:
    from feetech_cli.controller import FeetechServoController
    c = FeetechServoController(port, baudrate=BAUD)
    c.open()

    def set_zero() -> str:
        c.set_goal_position(1, 1700)                 # turn it off centre first
        wait(lambda: c.read_register(1, "present_position") == 1700)
        got = c.set_zero(1)
        expect(got == 2048, f"set-zero left present at {got}")
        return f"set-zero: present 2048, homing_offset {c.read_register(1, 'homing_offset')}"

    def wheel() -> str:
        c.set_operating_mode(1, 1)
        c.set_goal_velocity(1, -400)
        got = c.read_register(1, "present_velocity")
        c.set_torque(1, False)
        c.set_operating_mode(1, 0)
        expect(got == -400, f"present_velocity {got}")
        return "wheel mode: goal_velocity -400 -> present_velocity -400"

    check("feetech-cli", "set-zero (homing offset)", set_zero)
    check("feetech-cli", "wheel mode", wheel)
    c.close()


def st3215(port: str) -> None:
    from st3215 import ST3215
    s = ST3215(port)

    def middle() -> str:
        s.WritePosition(2, 2300)                     # turn it off centre first
        wait(lambda: s.ReadPosition(2) == 2300)
        expect(s.DefineMiddle(2) is True, "DefineMiddle failed")
        pos, corr = s.ReadPosition(2), s.ReadCorrection(2)
        expect(pos == 2048, f"position {pos} after DefineMiddle")
        return f"DefineMiddle (torque 128): position 2048, correction {corr}"

    def correct() -> str:
        s.CorrectPosition(3, -100)
        corr, pos = s.ReadCorrection(3), s.ReadPosition(3)
        expect(corr == -100 and pos == 2148, f"correction {corr}, position {pos}")
        return "CorrectPosition(-100): correction -100, position 2148"

    def rotate() -> str:
        s.Rotate(4, 500)
        mode, speed = s.ReadMode(4), s.ReadSpeed(4)[0]   # it returns (speed, comm, error)
        s.StopServo(4)
        s.SetMode(4, 0)
        expect(mode == 1 and speed == 500, f"mode {mode}, speed {speed}")
        return "Rotate(500): mode 1, speed 500"

    check("st3215", "DefineMiddle (STS centring)", middle)
    check("st3215", "CorrectPosition (offset)", correct)
    check("st3215", "Rotate (wheel mode)", rotate)


# ------------------------------------------------------------------ rustypot
def rustypot_sts(port: str) -> None:
    import rustypot
    c = rustypot.Sts3215PyController(port, BAUD, 0.1)

    def centre() -> str:
        c.write_raw_goal_position(5, 2200)           # turn it off centre first
        wait(lambda: c.read_raw_present_position(5) in ([2200], 2200))
        c.write_raw_torque_enable(5, 128)
        raw = c.read_raw_present_position(5)
        expect(raw == [2048] or raw == 2048, f"raw present {raw}")
        return f"torque 128: raw present 2048, offset {c.read_raw_homing_offset(5)}"

    def wheel() -> str:
        c.write_mode(6, 1)
        c.write_raw_goal_speed(6, 600)
        speed = c.read_raw_present_speed(6)
        c.write_torque_enable(6, False)
        c.write_mode(6, 0)
        expect(speed in ([600], 600), f"present speed {speed}")
        return "mode 1, goal speed 600 -> present speed 600"

    check("rustypot STS3215", "centring (torque 128)", centre)
    check("rustypot STS3215", "wheel mode", wheel)


def rustypot_xl430(port: str) -> None:
    import rustypot
    c = rustypot.Xl430PyController(port, BAUD, 0.1)

    def offset() -> str:
        before = c.read_present_position(1)
        c.write_homing_offset(1, 512)
        after = c.read_present_position(1)
        c.write_homing_offset(1, 0)
        expect(after[0] - before[0] == 512, f"present {before} -> {after}")
        return f"homing offset 512: present {before[0]} -> {after[0]}"

    def velocity() -> str:
        c.write_operating_mode(1, 1)
        c.write_torque_enable(1, 1)
        c.write_goal_velocity(1, 100)
        got = c.read_present_velocity(1)
        c.write_torque_enable(1, 0)
        c.write_operating_mode(1, 3)
        expect(got in ([100], 100), f"present velocity {got}")
        return f"velocity mode: goal 100 -> present {got}"

    check("rustypot XL430", "homing offset", offset)
    check("rustypot XL430", "velocity mode", velocity)


# ------------------------------------------------------------------ pypot, pyax12 (AX)
def pypot_ax(port: str) -> None:
    import pypot.dynamixel as pd
    io = pd.DxlIO(port, baudrate=BAUD, timeout=0.2)
    ids = [1, 2, 3, 4]

    limits = dict(zip(ids, io.get_angle_limit(ids), strict=True))

    def lost_sync_writes(n: int = 100) -> int:
        """Sync writes of goals (no reply) inside each joint's limits, each followed by a
        read of them back."""
        lost = 0
        for k in range(n):
            goals = {i: lo + (hi - lo) * (0.3 + 0.02 * (k % 20))
                     for i, (lo, hi) in limits.items()}
            io.set_goal_position(goals)
            got = io.get_goal_position(ids)
            lost += any(abs(g - goals[i]) > 0.3 for i, g in zip(ids, got, strict=True))
        return lost

    def flushes() -> str:
        lost = lost_sync_writes()
        expect(lost == 0, f"{lost} of 100 sync writes lost (pypot flushes its output "
                          "before each packet)")
        return "100 sync writes each followed by a flushed read: 0 lost"

    def no_flush() -> str:
        io._serial.flushOutput = lambda: None        # pypot without its output flush
        lost = lost_sync_writes()
        expect(lost == 0, f"{lost} of 100 sync writes lost without the flush")
        return "without flushOutput: 0 of 100 lost"

    def wheel() -> str:
        io.set_wheel_mode([1])
        io.enable_torque([1])
        io.set_moving_speed({1: -200.0})
        speed = io.get_present_speed([1])[0]
        load = io.get_present_load([1])[0]
        io.set_moving_speed({1: 0.0})
        io.set_joint_mode([1])
        expect(speed < -150, f"present speed {speed}")
        return f"wheel mode, moving speed -200 -> present speed {speed:.1f}, load {load:.1f} %"

    check("pypot", "flushOutput before each packet", flushes)
    check("pypot", "same, flushOutput disabled", no_flush)
    check("pypot", "wheel mode (velocity)", wheel)
    io.close()


def pyax12(port: str) -> None:
    from pyax12.connection import Connection
    c = Connection(port=port, baudrate=BAUD, timeout=0.2)   # reads 20 ms after a write

    def table() -> str:
        dump = c.dump_control_table(7)
        return f"control table dump: {len(dump)} bytes, model {c.get_model_number(7)}"

    def wheel() -> str:
        c.set_cw_angle_limit(7, 0)
        c.set_ccw_angle_limit(7, 0)
        c.write_data(7, 24, bytes([1]))
        c.set_speed(7, 512)
        speed = c.get_present_speed(7)
        c.set_speed(7, 0)
        expect(speed > 0, f"present speed {speed}")
        return f"wheel mode, speed 512 -> present speed {speed}"

    check("pyax12", "control table dump", table)
    check("pyax12", "wheel mode (velocity)", wheel)
    c.close()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--biped", default=".venv/bin/biped", help="the project's biped command")
    p.add_argument("--json", default=None, help="also write the results here")
    args = p.parse_args()
    plan: list[tuple[str, Callable[[str], None]]] = [
        ("feetech", lambda port: lerobot("feetech", port)), ("feetech", feetech_cli),
        ("feetech", st3215), ("feetech", rustypot_sts),
        ("dynamixel", lambda port: lerobot("dynamixel", port)), ("dynamixel", rustypot_xl430),
        ("dynamixel1", pypot_ax), ("dynamixel1", pyax12),
    ]
    for protocol, run in plan:
        with emulated(args.biped, protocol) as port:
            try:
                run(port)
            except Exception as e:  # noqa: BLE001 - a library that cannot even start
                name = getattr(run, "__name__", protocol)
                RESULTS.append({"library": name, "feature": "start", "ok": "False",
                                "seen": f"{type(e).__name__}: {e}"})
                print(f"{name:18s} {'start':34s} FAIL {type(e).__name__}: {e}", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(RESULTS, f, indent=1)
    return 0 if all(r["ok"] == "True" for r in RESULTS) else 1


if __name__ == "__main__":
    sys.exit(main())
