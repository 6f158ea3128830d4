"""A take's commands replayed in the simulation (``biped sim-gap``): where the simulated
servos are at each of the take's ticks when they get the same commands at the same times.

Two worlds, both driven by the one servo model (``sim.mujoco.servo_law``) with the robot
file's gains, physics and supply:

- ``robot``: the whole robot in MuJoCo (``MujocoBus``), standing on the floor, starting
  at the take's first read-back pose; each tick's command goes to the bus at the tick's
  time. For a take recorded on the real robot.
- ``bench``: every servo alone on a test bench (``sim.mujoco.pendulum``), carrying what
  ``loads`` says (joint name → a weight on an arm; nothing otherwise), from the take's
  first read-back position at rest. What ``biped emulate`` serves: its servos move by the
  same model, each on its own, so a take recorded on the emulator is replayed here.

Times: the take's ``t`` [s] (the loop's clock): command k holds from t_k to t_k+1.
Positions [rad, joint angles] at tick k are the state when tick k's read-back was in
(``present_t``; t_k in a take without it), command k applied since t_k.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.motion.takes import Take
from robot.servo.bench_load import NONE, BenchLoad
from robot.servo.firmware import LOG_GAIN_REGISTERS
from robot.servo.pendulum_log import DT, PendulumLog
from sim.mujoco.bus import MujocoBus
from sim.mujoco.pendulum import PendulumBench

Floats = npt.NDArray[np.float64]
WORLDS = ("robot", "bench")
#: An unloaded bench servo still turns its horn; the pendulum rig needs a mass: 1 g at
#: 3 cm (9e-7 kg m^2, the emulator's horn 1e-6; 0.3 mN m of gravity at most, against a
#: gearbox friction of 10-50 mN m).
_HORN = BenchLoad(mass=0.001, length=0.03)


def first_read(take: Take) -> tuple[int, Floats]:
    """The first tick with a read-back, and what it read [rad]; ConfigError without any."""
    present = take.present
    rows = (np.zeros(0, dtype=np.int64) if present is None
            else np.flatnonzero(np.isfinite(present).all(axis=1)))
    if not len(rows):
        raise ConfigError(f"{take.source}: no read-back positions (\"present\") in it: record "
                          "the take on a servo bus (biped walk --bus ... --record "
                          "NAME.take.jsonl)")
    k = int(rows[0])
    assert present is not None
    return k, present[k]


def replay(robot: RobotConfig, take: Take, *, world: str = "robot",
           loads: Mapping[str, BenchLoad] | None = None) -> Floats:
    """Simulated joint angles [rad], ticks x joints (NaN before the first read-back)."""
    if world not in WORLDS:
        raise ConfigError(f"--world: expected one of {', '.join(WORLDS)}, got {world!r}")
    if tuple(take.header.joints) != tuple(robot.joint_names):
        raise ConfigError(f"{take.source}: its joints ({len(take.header.joints)}) are not "
                          f"robot {robot.name!r}'s ({len(robot.joint_names)}); pass the robot "
                          "file it was recorded with (--robot)")
    start, q0 = first_read(take)
    out = np.full_like(take.q, np.nan)
    t = take.t[start:] - take.t[start]
    read = (take.t if take.present_t is None else take.present_t)[start:] - take.t[start]
    read = np.maximum(read, t)
    cmd = take.q[start:]
    sim = (_robot(robot, t, read, cmd, q0) if world == "robot"
           else _bench(robot, t, read, cmd, q0, loads or {}))
    out[start:] = sim
    return out


def _robot(robot: RobotConfig, t: Floats, read: Floats, cmd: Floats, q0: Floats) -> Floats:
    bus = MujocoBus(robot, pose=dict(zip(robot.joint_names, q0.tolist(), strict=True)))
    bus.open()
    try:
        sm = bus.servo_map
        bus.set_torque(robot.ids, enabled=True)
        out = np.empty_like(cmd)
        for k in range(len(t)):
            bus.advance(float(t[k]))
            bus.write_goals(sm.goals(cmd[k].tolist()))
            bus.advance(float(read[k]))
            out[k] = sm.to_rad(bus.present_ticks())
        return out
    finally:
        bus.close()


def _bench(robot: RobotConfig, t: Floats, read: Floats, cmd: Floats, q0: Floats,
           loads: Mapping[str, BenchLoad]) -> Floats:
    unknown = sorted(set(loads) - set(robot.joint_names))
    if unknown:
        raise ConfigError(f"--load: no joint {unknown[0]!r}; valid: "
                          f"{', '.join(robot.joint_names)}")
    out = np.empty_like(cmd)
    groups: dict[str, list[int]] = {}
    for j, name in enumerate(robot.joint_names):
        joint = robot.joint(name)
        key = f"{robot.servo(joint).name}/{robot.voltage(joint)}/{robot.servo_physics(joint)!r}"
        groups.setdefault(key, []).append(j)      # one bench per model, supply and physics
    grid = np.arange(0.0, max(t[-1], read[-1]) + DT, DT)
    held = cmd[np.searchsorted(t, grid, side="right") - 1]   # each command holds until the next
    for columns in groups.values():
        joints = [robot.joint(robot.joint_names[j]) for j in columns]
        model, physics = robot.servo(joints[0]), robot.servo_physics(joints[0])
        logs = [_log(robot, jt.name, grid, held[:, j], q0[j], loads.get(jt.name, NONE))
                for j, jt in zip(columns, joints, strict=True)]
        bench = PendulumBench(logs, model)
        simulated = bench.replay(physics)
        for row, j in enumerate(columns):
            out[:, j] = np.interp(read, grid[:bench.steps], simulated[row, :len(grid)])
    return out


def _log(robot: RobotConfig, name: str, t: Floats, goal: Floats, q0: float,
         load: BenchLoad) -> PendulumLog:
    """The bench run of joint ``name``: the commands as the goal, at rest at ``q0``; its
    gains: the model's factory values with the P register the robot file's (the bench's
    gain set, ``firmware.log_gains``)."""
    joint = robot.joint(name)
    physics = robot.servo_physics(joint)
    registers = LOG_GAIN_REGISTERS[physics.law]
    kp = robot.gains(joint)[registers[0]] if registers else 0
    rig = load if load.mass > 0 else _HORN
    held = np.full_like(t, q0)
    zeros = np.zeros_like(t)
    return PendulumLog(source=name, mass=rig.mass, length=rig.length, kp=kp,
                       vin=robot.voltage(joint), motor=robot.servo(joint).name,
                       trajectory="take", t=t, goal=goal, position=held, speed=zeros,
                       torque_enable=np.ones(len(t), dtype=bool), load=zeros,
                       input_volts=zeros + robot.voltage(joint), temp=zeros,
                       arm_mass=rig.arm_mass)
