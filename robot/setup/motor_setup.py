"""Giving a factory-new servo its joint's id and the robot's baud rate (``biped setup-motors``).

Only one servo may be on the bus. ``find_servo`` looks for it in two passes, cheapest first:

1. the factory id 1 at every standard baud of the family, and the robot's own ids at the
   robot's baud (a servo set up earlier and left on the chain), most likely bauds first;
2. if nothing answered: every id 0..252 at each baud (one broadcast ping per baud where the
   protocol has it: Dynamixel Protocol 2.0, and LX's broadcast id read; else one ping per
   id: Dynamixel Protocol 1.0, Feetech), stopping at the first baud that answers.

More than one servo, or a garbled reply (two servos sharing an id answer at once), refuses
before anything is written; no answer at all says "no servo answered". A lone servo that
answers as another joint's id at the robot's baud (``set_up_already``) is a servo set up
earlier: the command asks before it takes it (refuses under ``--yes``), because a lost
ping of the new servo would otherwise leave the old one looking alone. ``assign`` then
writes, torque off first (EEPROM): return delay 0, the id, the baud rate; re-opens at the
new baud and checks the id and model answer.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from robot.bus.lx.bus import LxBus
from robot.bus.sdk.bus import SdkBus
from robot.bus.tables import EEPROM_LOCK, RETURN_DELAY_UNIT_S
from robot.config.robot import SERVO_ID, JointConfig, RobotConfig
from robot.errors import BusError, ConfigError
from robot.servo.models import BAUD_CODES, BUS_FAMILIES, FACTORY_BAUD, lookup, model_name

log = logging.getLogger(__name__)

FACTORY_ID = 1
# Baud rates as shipped: robot.servo.models.FACTORY_BAUD (per family; a model may differ:
# the MX series on Protocol 1.0 ships at 57600 where the AX ships at 1 Mbps). LX servos
# have one rate (no Baud Rate register) and find a lone servo by a broadcast ID read
# (robot/bus/lx/bus.py).
__all__ = ["FACTORY_BAUD", "find_servo", "set_up_already", "assign"]
#: The buses setup-motors drives (LX: the same calls, on its own protocol).
SetupBus = SdkBus | LxBus
ALL_IDS = range(int(SERVO_ID.lo), int(SERVO_ID.hi) + 1)


class SetupRefused(ConfigError):
    """setup-motors will not write: not exactly one servo, or the wrong model (exit 2)."""


@dataclass(frozen=True)
class Found:
    """A servo that answered: its id, baud [bit/s] and model number."""

    id: int
    baud: int
    model: int


def baud_order(family: str, robot_baud: int) -> list[int]:
    """The family's standard bauds, most likely first: factory, the robot's, then the rest
    fastest first (hobby setups favour 1 Mbps and up)."""
    rest = sorted(BAUD_CODES.get(family, {}).values(), reverse=True)
    first = [FACTORY_BAUD[family], robot_baud]
    return list(dict.fromkeys(first + rest))


def _shared_id(bus: SetupBus, sid: int, sign: str) -> SetupRefused:
    return SetupRefused(f"more than one servo answers as id {sid} at {bus.baud} baud on "
                        f"{bus.port_name} ({sign}); nothing was written: connect only the "
                        "servo to set up")


def _ping_all(bus: SetupBus, ids: Iterable[int]) -> list[Found]:
    found = []
    for sid in ids:
        try:
            model = bus.ping(sid)
        # IndexError: scservo_sdk's ping reads the model number next, and takes a second
        # servo's late ping reply for it (too short: it indexes past its end).
        except (BusError, IndexError) as e:
            raise _shared_id(bus, sid, "garbled replies") from e
        if model is None:
            continue
        if bus.stray_bytes():
            raise _shared_id(bus, sid, "a second reply")
        found.append(Found(sid, bus.baud, model))
    return found


def _sweep(bus: SetupBus, progress: Callable[[str], None]) -> list[Found]:
    """Every servo at the current baud: a broadcast ping, else (the protocol has none) one
    ping per id."""
    try:
        answered = bus.broadcast_ping()
    except BusError as e:   # its message says why (garbled replies, a port error) and the fix
        raise SetupRefused(f"{e}; nothing was written") from e
    if answered is None:
        progress(f"scanning every id at {bus.baud} baud (one ping per id: this protocol has "
                 "no broadcast ping)")
        return _ping_all(bus, ALL_IDS)
    progress(f"scanning every id at {bus.baud} baud (one broadcast ping)")
    return _ping_all(bus, sorted(answered))  # one by one: duplicates collapse in the reply


def _try_baud(bus: SetupBus, baud: int) -> bool:
    """Switch to ``baud``; False (logged) for a rate the SDK cannot set (scservo_sdk has
    no 76800)."""
    try:
        bus.set_baud(baud)
    except BusError as e:
        log.info("skipping %d baud: %s", baud, e)
        return False
    return True


def find_servo(bus: SetupBus, robot: RobotConfig, *,
               progress: Callable[[str], None] = log.info) -> Found:
    """The one servo on ``bus`` (open; left at its original baud). SetupRefused when none,
    or more than one, answers."""
    return find_servos(bus, robot, 1, progress=progress)[0]


def find_servos(bus: SetupBus, robot: RobotConfig, count: int, *,
                progress: Callable[[str], None] = log.info) -> list[Found]:
    """The ``count`` servos on ``bus`` (one case: 1, or 2 for a dual-axis servo, which ships
    at ids 1 and 2); left at its original baud. SetupRefused when none, or another number,
    answers."""
    family = robot.bus.servo.family
    original = bus.baud
    try:
        bauds = [b for b in baud_order(family, robot.bus.baud) if _try_baud(bus, b)]
        skipped = sorted(set(BAUD_CODES.get(family, {}).values()) - set(bauds))
        factory_ids = list(range(FACTORY_ID, FACTORY_ID + count))
        progress(f"looking for id {', '.join(map(str, factory_ids))} at "
                 f"{', '.join(map(str, bauds))} baud"
                 + (f" ({', '.join(map(str, skipped))}: the SDK cannot set it)" if skipped
                    else ""))
        found: list[Found] = []
        for baud in bauds:
            bus.set_baud(baud)
            ids = factory_ids + ([i for i in robot.ids if i not in factory_ids]
                                 if baud == robot.bus.baud else [])
            found += _ping_all(bus, ids)
        if not found:
            for baud in bauds:
                bus.set_baud(baud)
                found = _sweep(bus, progress)
                if found:
                    break
    finally:
        bus.set_baud(original)
    if not found:
        rates = ", ".join(map(str, bauds))
        raise SetupRefused(f"no servo answered on {bus.port_name} at any id "
                           f"({ALL_IDS.start}-{ALL_IDS.stop - 1}) and baud ({rates}); check "
                           "its power (the LED flashes at power-up), its cable and --port")
    who = ", ".join(f"id {f.id} at {f.baud} baud" for f in found)
    if count == 1 and len(found) > 1:
        raise SetupRefused(f"{len(found)} servos answer on {bus.port_name} ({who}); nothing "
                           "was written: connect only the servo to set up")
    if count > 1 and (len(found) != count or len({(f.baud, f.model) for f in found}) != 1):
        raise SetupRefused(f"{len(found)} servo(s) answer on {bus.port_name} ({who}); a "
                           f"dual-axis case answers at {count} ids of one model and baud; "
                           "nothing was written: connect only the case to set up")
    return found


def set_up_already(found: Sequence[Found], robot: RobotConfig,
                   case: Sequence[JointConfig]) -> list[tuple[Found, JointConfig]]:
    """The servos in ``found`` that answer as another joint's id at the robot's baud: set
    up earlier for that joint. A factory id (1, or 1 and 2 for a dual-axis case) is not
    counted: a new servo answers there too, so it cannot be told apart."""
    own = {j.servo_id for j in case}
    factory = range(FACTORY_ID, FACTORY_ID + len(case))
    taken = []
    for f in found:
        other = robot.joint_by_id(f.id)
        if (other is not None and f.baud == robot.bus.baud and f.id not in own
                and f.id not in factory):
            taken.append((f, other))
    return taken


def check_model(found: Found, robot: RobotConfig, joint: JointConfig) -> str | None:
    """SetupRefused unless the found servo is the joint's model; a note (returned) when the
    model's number is unverified and the servo reports a number no known model has."""
    want = robot.servo(joint)
    if found.model == want.number:
        return None
    families = BUS_FAMILIES[robot.bus.kind]
    if not want.number_verified and lookup(families, found.model) is None:
        return (f"the servo reports model number {found.model}, which no page at hand names; "
                f"{want.name}'s own number is unverified: taken as the {want.name} the robot "
                "file names")
    raise SetupRefused(
        f"the servo at id {found.id}, {found.baud} baud is a "
        f"{model_name(families, found.model)} (model {found.model}), but {robot.name} uses "
        f"{want.name} (model {want.number}) for {joint.name}; nothing was written: connect "
        f"a {want.name}, or fix bus.model in {robot.source}")


def _write_tolerant(bus: SetupBus, sid: int, name: str, value: int,
                    confirm: Callable[[], bool]) -> None:
    """Write a register whose effect may change how (or whether) the status reply comes
    back (id, baud); a failed reply is fine when ``confirm()`` then sees the change."""
    try:
        bus.write_register(sid, name, value)
    except BusError:
        if not confirm():
            raise


def assign(bus: SetupBus, found: Found, joint: JointConfig, robot: RobotConfig) -> list[str]:
    """Give the one servo ``found`` the joint's id, the robot's baud and return delay 0;
    verify at the new baud. Returns what changed, in words. ``bus`` is open; it ends at the
    robot's baud."""
    family = robot.bus.servo.family
    codes = {b: c for c, b in BAUD_CODES.get(family, {}).items()}
    new_id, new_baud = joint.servo_id, robot.bus.baud
    bus.set_baud(found.baud)
    sid = found.id
    bus.set_torque([sid], enabled=False)
    # Feetech: unlock the EEPROM so the writes survive a power cycle. (The AX's Lock(47)
    # means the opposite: 1 locks the EEPROM until power-off, so it is never written.)
    lock = EEPROM_LOCK.get(family)
    if lock:
        bus.write_register(sid, lock[0], lock[1])
    changes: list[str] = []
    delay = bus.read_register(sid, "return_delay_time") if "return_delay_time" in bus.table else 0
    if delay:
        bus.write_register(sid, "return_delay_time", 0)
        us = delay * RETURN_DELAY_UNIT_S[family] * 1e6
        changes.append(f"return delay {us:.0f} µs -> 0 (every reply waited that long)")
    if sid != new_id:
        _write_tolerant(bus, sid, "id", new_id, lambda: bus.ping(new_id) is not None)
        changes.append(f"id {sid} -> {new_id}")
        sid = new_id
    if found.baud != new_baud:
        def answers_at_new_baud() -> bool:
            bus.set_baud(new_baud)
            return bus.ping(sid) is not None

        _write_tolerant(bus, sid, "baud_rate", codes[new_baud], answers_at_new_baud)
        changes.append(f"baud {found.baud} -> {new_baud}")
    bus.set_baud(new_baud)
    model = bus.ping(sid)
    if model != found.model:
        raise BusError(f"{joint.name}: after the writes the servo does not answer as id {sid} "
                       f"at {new_baud} baud on {bus.port_name} (got {model}); power-cycle it "
                       f"and rerun `biped setup-motors --joint {joint.name}`")
    if lock:
        bus.write_register(sid, lock[0], lock[2])
    return changes


def answered(ask: Callable[[str], str], consequence: str) -> Callable[[str], str]:
    """``ask`` with end of input (stdin closed, Ctrl-D) turned into a one-line ConfigError."""
    def wrapped(prompt: str) -> str:
        try:
            return ask(prompt)
        except EOFError:
            raise ConfigError(f"input ended before the last prompt was answered; "
                              f"{consequence}") from None
    return wrapped


def joints_to_set(robot: RobotConfig, name: str | None) -> Sequence[JointConfig]:
    """The joint ``name`` (ConfigError naming the valid ones), or every joint in order."""
    return [robot.joint(name)] if name else list(robot.joints)
