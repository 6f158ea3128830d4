"""Which servos an emulated chain holds: model, baud, ids and each servo's limits.

From a robot config (its bus kind, model and baud, each joint's zero and limits in ticks)
or from explicit ids; checked against the emulator's own model list and baud codes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from robot.config.robot import RobotConfig
from robot.config.servo_file import physics_for
from robot.servo.bench_load import NONE, BenchLoad
from robot.servo.models import MODELS as DRIVER_MODELS
from sim.emulator.control_tables import BAUD_CODES, TABLES
from sim.emulator.lx_commands import BAUD as LX_BAUD
from sim.emulator.records import EmulatorError
from sim.emulator.servo import ServoSpec
from sim.emulator.servo_dynamics import DynamicsSpec
from sim.emulator.servo_models import MODELS, PROTOCOL_FAMILIES, PROTOCOL_FAMILY

DEFAULT_MODEL = {"dynamixel": "XL430-W250", "dynamixel1": "AX-12A", "feetech": "STS3215",
                 "lx": "LX-16A"}
DEFAULT_BAUD = 1_000_000
# As shipped: ROBOTIS e-Manual XL430-W250 (Baud Rate(8) initial 1 = 57600, Return Delay
# Time(9) initial 250 = 500 us, ID(7) initial 1); Feetech STS memory table (ID(5) 1, Baud
# Rate(6) 0 = 1 Mbps, Return Delay Time(7) 0); e-Manual AX-12A (ID(3) 1, Baud Rate(4) 1 =
# 1 Mbps, Return Delay Time(5) 250 = 500 us).
# LX: one rate, 115200, and no return delay register (sim/emulator/lx_commands.py).
FACTORY_BAUD = {"dynamixel": 57_600, "dynamixel1": 1_000_000, "feetech": 1_000_000,
                "lx": LX_BAUD}
FACTORY_RETURN_DELAY = {"dynamixel": 250, "dynamixel1": 250, "feetech": 0, "lx": 0}
#: The rates each family's servos listen at [bit/s].
RATES: dict[str, list[int]] = {**{f: sorted(c.values()) for f, c in BAUD_CODES.items()},
                               "lx": [LX_BAUD]}
FACTORY_ID = 1
#: How emulated servos move: by the servo model, or constant-speed travel (plan_dynamics).
MOTIONS = ("model", "travel")


@dataclass(frozen=True)
class ChainChoice:
    """model: the chain's default model; baud [bit/s]; ids in bus order; one spec each;
    dynamics: each servo's model (``plan_dynamics``)."""

    model: str
    baud: int
    ids: tuple[int, ...]
    servos: tuple[ServoSpec, ...]
    dynamics: tuple[DynamicsSpec | None, ...] = ()


def _limits(robot: RobotConfig | None, servo_id: int, model: str) -> tuple[int, int, int]:
    """(zero, min, max) [ticks] for ``servo_id`` from the robot's joint, else the full range
    with the horn at its middle (2048 of 4096; 512 of the AX's 1024)."""
    resolution = MODELS[model].resolution
    joint = robot.joint_by_id(servo_id) if robot is not None else None
    if joint is None:
        return resolution // 2, 0, resolution - 1
    per_rad = MODELS[model].ticks_per_rad
    ends = [joint.zero_ticks + joint.sign * q * per_rad for q in (joint.min_rad, joint.max_rad)]
    lo = max(0, math.floor(min(ends)))
    hi = min(resolution - 1, math.ceil(max(ends)))
    return joint.zero_ticks, lo, hi


def plan_chain(protocol: str, robot: RobotConfig | None, *, ids: Sequence[int] | None,
               model: str | None, baud: int | None,
               loads: Mapping[int, BenchLoad] | None = None, motion: str = "travel"
               ) -> ChainChoice:
    """The chain ``Emulator(protocol, robot, ids=, model=, baud=)`` serves; EmulatorError
    (one line, naming the argument and its valid values) when something does not fit."""
    if protocol not in PROTOCOL_FAMILY:
        raise EmulatorError(f"protocol: expected one of {', '.join(PROTOCOL_FAMILY)}, "
                            f"got {protocol!r}")
    same_kind = robot is not None and robot.bus.kind == protocol
    model = model or (robot.bus.model if robot is not None and same_kind
                      else DEFAULT_MODEL[protocol])
    if model not in MODELS or MODELS[model].family not in PROTOCOL_FAMILIES[protocol]:
        valid = [m for m, s in MODELS.items() if s.family in PROTOCOL_FAMILIES[protocol]]
        raise EmulatorError(f"model: {model!r} is not a {protocol} servo; valid: "
                            f"{', '.join(valid)}")
    family = MODELS[model].family              # one table family a chain (as the driver's bus)
    if ids is None:
        if robot is None:
            raise EmulatorError("Emulator needs a robot config or ids=[...]")
        ids = robot.ids
    baud = baud or (robot.bus.baud if robot is not None and same_kind else
                    FACTORY_BAUD[protocol] if family == "lx" else DEFAULT_BAUD)
    if baud not in RATES[family]:
        raise EmulatorError(f"baud: {baud} is not a {protocol} rate; valid: {RATES[family]}")
    specs = []
    cases: dict[str, int] = {}          # a dual-axis case's name -> its number (1, 2, ...)
    for sid in ids:
        joint = robot.joint_by_id(sid) if robot is not None and same_kind else None
        own = joint.model if joint is not None and joint.model else model  # mixed models
        zero, lo, hi = _limits(robot, sid, own)
        case = cases.setdefault(joint.case, len(cases) + 1) if joint and joint.case else 0
        specs.append(ServoSpec(sid, own, zero, lo, hi, baud, case=case))
    return ChainChoice(model, baud, tuple(ids), tuple(specs),
                       plan_dynamics(protocol, robot, specs, loads or {}, motion=motion))


def factory_servos(protocol: str, servos: Sequence[ServoSpec]) -> tuple[ServoSpec, ...]:
    """The same servos with the factory return delay (new out of the box): the manual's
    initial Return Delay Time of each one's table (LX: none). A dual-axis model
    (2XL430-W250) is a case of two axes, at ids 1 and 2."""
    servos = [replace(s, servo_id=s.servo_id + axis, case=n + 1) if MODELS[s.model].axes == 2
              else s for n, s in enumerate(servos)
              for axis in range(MODELS[s.model].axes)]

    def delay(model: str) -> int:
        entry = TABLES.get(MODELS[model].layout, {}).get("return_delay_time")
        return entry.initial or 0 if entry is not None else FACTORY_RETURN_DELAY[protocol]
    return tuple(replace(s, return_delay=delay(s.model)) for s in servos)


def factory_baud(protocol: str, model: str | None) -> int:
    """The rate a new ``model`` servo (default: the protocol's) listens at [bit/s]: its
    table's initial Baud Rate (an MX-28 on Protocol 1.0 ships at 57600 where an AX-12A
    ships at 1 Mbps; the XL-320 at 1 Mbps where the X series ships at 57600)."""
    m = MODELS[model or DEFAULT_MODEL[protocol]]
    entry = TABLES.get(m.layout, {}).get("baud_rate")
    if entry is None or entry.initial is None:
        return FACTORY_BAUD[protocol]
    return BAUD_CODES[m.family][entry.initial]


def plan_dynamics(protocol: str, robot: RobotConfig | None, servos: Sequence[ServoSpec],
                  loads: Mapping[int, BenchLoad], *, motion: str = "travel"
                  ) -> tuple[DynamicsSpec | None, ...]:
    """Each servo's model (``sim.emulator.servo_dynamics``): its physics and supply from the
    robot file where a joint has its id (the model file it names, ``bus.voltage``), else its
    model's bundled physics at the nominal voltage; ``loads``: id → what it carries.

    ``motion="travel"``: no model, the horn travels to the goal at constant speed and stops
    on it (for tests of register semantics that want exact positions). LX servos (no
    control table) always travel."""
    if motion not in MOTIONS:
        raise EmulatorError(f"motion: expected one of {', '.join(MOTIONS)}, got {motion!r}")
    unknown = sorted(set(loads) - {s.servo_id for s in servos})
    if unknown:
        raise EmulatorError(f"load: no servo with id {unknown[0]} in the chain; ids: "
                            f"{sorted({s.servo_id for s in servos})}")
    if PROTOCOL_FAMILY[protocol] == "lx" or motion == "travel":
        if loads:
            raise EmulatorError("load: only a servo that moves by its model carries a load "
                                "(dynamixel, dynamixel1, feetech; motion 'model')")
        return tuple(None for _ in servos)
    same_kind = robot is not None and robot.bus.kind == protocol
    out: list[DynamicsSpec | None] = []
    for s in servos:
        joint = robot.joint_by_id(s.servo_id) if robot is not None and same_kind else None
        driver = DRIVER_MODELS.get(s.model)
        if driver is None or not driver.gain_set:
            out.append(None)       # no firmware law for it: it travels
            continue
        if robot is not None and joint is not None and robot.servo(joint).name == s.model:
            physics, voltage = robot.servo_physics(joint), robot.voltage(joint)
        else:
            physics = physics_for(s.model)
            voltage = DRIVER_MODELS[s.model].nominal_voltage
        out.append(DynamicsSpec(s.model, physics, voltage, s.zero_ticks,
                                loads.get(s.servo_id, NONE)))
    return tuple(out)
