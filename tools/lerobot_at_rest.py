"""LeRobot's DynamixelMotorsBus on `biped emulate` (issue 34): goals to unloaded XL430s at
factory gains, and where each comes to rest. A maintainer's check, not part of `make test`
(LeRobot pulls in PyTorch): run it from a scratch venv that has LeRobot's motors package,

    python3 -m venv /tmp/lr && /tmp/lr/bin/pip install dynamixel-sdk deepdiff tqdm
    /tmp/lr/bin/pip install --no-deps lerobot             # its motors package only
    /tmp/lr/bin/python tools/lerobot_at_rest.py --biped .venv/bin/biped [--baud 57600]

(torch, accelerate and datasets are replaced by empty modules, as in
docs/third_party_check.py: the motor bus imports them and never calls them.)

What a real XL430 does there is docs/servos.md's "At rest": it stops short of its goal, by
4-5 pulses in a published report, by under 3 in the model (its friction over P 640); a
servo that settles within a tick has no friction, or an I term. The script prints goal,
present and the shortfall per servo and exits 1 when one is outside 1..5 pulses on the
side it came from, or did not come to rest within 10 s.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "docs"))
from third_party_check import shim_lerobot_imports  # noqa: E402

GOALS = {1: 2148, 2: 1948, 3: 2200}
SHORT = (1, 5)          # pulses short of the goal at rest (docs/servos.md, "At rest")


def bus_on(port: str, baud: int) -> Any:
    shim_lerobot_imports()
    from lerobot.motors import Motor, MotorNormMode
    from lerobot.motors.dynamixel import DynamixelMotorsBus
    motors = {f"j{i}": Motor(i, "xl430-w250", MotorNormMode.RANGE_M100_100) for i in GOALS}
    bus = DynamixelMotorsBus(port, motors)
    bus.default_baudrate = baud
    bus.connect()
    return bus


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--biped", default=".venv/bin/biped", help="the project's biped command")
    p.add_argument("--baud", type=int, default=1_000_000, help="chain baud [bit/s]")
    args = p.parse_args()
    emu = subprocess.Popen([args.biped, "emulate", "--protocol", "dynamixel", "--robot",
                            "biped18-dynamixel", "--baud", str(args.baud)],
                           stdout=subprocess.PIPE, text=True)
    try:
        assert emu.stdout is not None
        bus = bus_on(emu.stdout.readline().strip(), args.baud)
        start = bus.sync_read("Present_Position", normalize=False)
        bus.enable_torque()
        bus.sync_write("Goal_Position", {f"j{i}": g for i, g in GOALS.items()},
                       normalize=False)
        seen: list[dict[str, int]] = []
        end = time.monotonic() + 10.0
        while time.monotonic() < end and not (len(seen) > 5 and all(
                s == seen[-1] for s in seen[-5:])):
            seen.append(bus.sync_read("Present_Position", normalize=False))
            time.sleep(0.05)
        bus.disable_torque()
        bus.disconnect()
    finally:
        emu.terminate()
        emu.wait(10)
    ok = len(seen) > 5 and all(s == seen[-1] for s in seen[-5:])
    for i, goal in GOALS.items():
        name, at = f"j{i}", seen[-1][f"j{i}"]
        short = goal - at if goal > start[name] else at - goal
        good = SHORT[0] <= short <= SHORT[1]
        ok = ok and good
        print(f"servo {i}: from {start[name]} to goal {goal}: rests at {at}, {short} pulses "
              f"short {'ok' if good else 'OUTSIDE ' + str(SHORT)}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
