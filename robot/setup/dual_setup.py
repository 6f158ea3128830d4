"""Setting up a dual-axis servo (2XL430-W250, 2XC430-W250): one case, two ids.

The e-Manual (2XL430-W250, "Control Table Description"): each axis has its own control
table and id; the Baud Rate(8) and Protocol Version(13) are one setting for both (writing
one axis changes the other); giving the two axes the same id is refused with a Data Limit
Error. So setup-motors connects a whole case at once (the user is asked for the case, not
one servo), finds the two axes (they ship at ids 1 and 2), and gives them the two joints of
the case in order: the axis answering at the lower id takes the joint listed first in the
robot file. Ids are changed so that no write ever names the other axis's id (through a
free temporary id when the two swap), the baud rate is written once and both axes are
checked at the new rate. Which physical axis is which the user checks after with
``biped monitor`` (and calibrate measures each joint's sign anyway).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from robot.config.robot import SERVO_ID, JointConfig, RobotConfig
from robot.errors import BusError
from robot.servo.models import BAUD_CODES
from robot.setup.motor_setup import Found, SetupBus, _write_tolerant


def id_moves(current: Sequence[int], target: Sequence[int]) -> list[tuple[int, int]]:
    """(from, to) id writes that take the axes at ``current`` to ``target`` (index by
    index) without ever naming an id another axis holds at that moment."""
    held = list(current)
    moves: list[tuple[int, int]] = []
    pending = [i for i in range(len(held)) if held[i] != target[i]]
    while pending:
        free = [i for i in pending if target[i] not in held]
        if not free:      # a swap: park one axis at an id nobody holds or wants
            i = pending[0]
            spare = next(n for n in range(int(SERVO_ID.hi), int(SERVO_ID.lo), -1)
                         if n not in held and n not in target)
            moves.append((held[i], spare))
            held[i] = spare
            continue
        for i in free:
            moves.append((held[i], target[i]))
            held[i] = target[i]
        pending = [i for i in pending if held[i] != target[i]]
    return moves


def _answers(bus: SetupBus, sid: int) -> Callable[[], bool]:
    return lambda: bus.ping(sid) is not None


def assign_case(bus: SetupBus, found: Sequence[Found], joints: Sequence[JointConfig],
                robot: RobotConfig) -> list[str]:
    """Give the two axes ``found`` (one case) the ids of ``joints`` (the case's joints in
    file order), the robot's baud and return delay 0; verify both at the new baud. Returns
    what changed, in words; ``bus`` ends at the robot's baud."""
    axes = sorted(found, key=lambda f: f.id)
    family = robot.bus.servo.family
    new_baud, old_baud = robot.bus.baud, axes[0].baud
    bus.set_baud(old_baud)
    ids = [f.id for f in axes]
    bus.set_torque(ids, enabled=False)
    changes: list[str] = []
    for sid in ids:
        if bus.read_register(sid, "return_delay_time"):
            bus.write_register(sid, "return_delay_time", 0)
            changes.append(f"return delay of id {sid} -> 0")
    targets = [j.servo_id for j in joints]
    for old, new in id_moves(ids, targets):
        _write_tolerant(bus, old, "id", new, _answers(bus, new))
    changes += [f"id {f.id} -> {j.servo_id} ({j.name})" for f, j in zip(axes, joints,
                                                                          strict=True)
                if f.id != j.servo_id]
    if old_baud != new_baud:
        code = {b: c for c, b in BAUD_CODES[family].items()}[new_baud]

        def both_answer() -> bool:
            bus.set_baud(new_baud)
            return all(bus.ping(t) is not None for t in targets)

        # One write: the case has one communication module, the other axis follows.
        _write_tolerant(bus, targets[0], "baud_rate", code, both_answer)
        changes.append(f"baud {old_baud} -> {new_baud} (both axes: one setting)")
    bus.set_baud(new_baud)
    for f, j in zip(axes, joints, strict=True):
        model = bus.ping(j.servo_id)
        if model != f.model:
            raise BusError(f"{j.name}: after the writes the axis does not answer as id "
                           f"{j.servo_id} at {new_baud} baud on {bus.port_name} (got {model});"
                           f" power-cycle the case and rerun `biped setup-motors --joint "
                           f"{joints[0].name}`")
    return changes
