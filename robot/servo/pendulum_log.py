"""Pendulum logs: a servo swinging a known weight on an arm while following a goal
trajectory, in the public JSON format of Rhoban/bam's recorders (so logs from either tool
serve the other). ``.json`` or gzip-compressed ``.json.gz``.

Top level: ``mass`` [kg] at ``length`` [m] on the output shaft (``arm_mass`` [kg], a
uniform arm, optional), ``kp`` (the position P register during the run), ``vin`` [V],
``motor``, ``trajectory`` (a name), ``entries``: one per sample with ``timestamp`` [s],
``goal_position``, ``position`` [rad] (0: arm hanging down), ``speed`` [rad/s], ``load``,
``input_volts`` [V], ``temp`` [deg C], ``torque_enable``.

What a log must satisfy (finite numbers, a real weight on a real arm, time moving forward
over a plausible span, a ``kp`` its register can hold): ``robot.servo.log_rules``; every
log read is checked, so ``identify fit`` and ``check`` never replay a broken one.
"""

from __future__ import annotations

import gzip
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robot.errors import ConfigError
from robot.files.atomic import write_bytes
from robot.servo import log_rules as rules

Floats = npt.NDArray[np.float64]
#: The resampling period of ``identify check`` and ``fit`` [s].
DT = 0.005
_SERIES = ("goal_position", "position", "speed", "load", "input_volts", "temp")


@dataclass(frozen=True)
class PendulumLog:
    """One log, as arrays over samples (see the module docstring for the fields)."""

    source: str
    mass: float
    length: float
    kp: int
    vin: float
    motor: str
    trajectory: str
    t: Floats
    goal: Floats
    position: Floats
    speed: Floats
    torque_enable: npt.NDArray[np.bool_]
    load: Floats
    input_volts: Floats
    temp: Floats
    arm_mass: float = 0.0

    @property
    def name(self) -> str:
        return Path(self.source).name

    def resampled(self, dt: float = DT) -> PendulumLog:
        """Linear interpolation onto t = 0, dt, 2 dt, ... up to the last sample (torque
        enable: the nearer sample's)."""
        t = np.arange(0.0, self.t[-1], dt)

        def lin(y: Floats) -> Floats:
            return np.interp(t, self.t, y)

        enable = np.interp(t, self.t, self.torque_enable.astype(float)) > 0.5
        return PendulumLog(self.source, self.mass, self.length, self.kp, self.vin, self.motor,
                           self.trajectory, t, lin(self.goal), lin(self.position),
                           lin(self.speed), enable, lin(self.load), lin(self.input_volts),
                           lin(self.temp), self.arm_mass)

    def to_json(self) -> dict[str, object]:
        entries = [{"timestamp": round(float(t), 6), "goal_position": round(float(g), 6),
                    "position": round(float(q), 6), "speed": round(float(v), 5),
                    "load": round(float(ld), 4), "input_volts": round(float(u), 3),
                    "temp": round(float(c), 2), "torque_enable": bool(e)}
                   for t, g, q, v, ld, u, c, e in zip(
                       self.t, self.goal, self.position, self.speed, self.load,
                       self.input_volts, self.temp, self.torque_enable, strict=True)]
        head: dict[str, object] = {"mass": self.mass, "length": self.length, "kp": self.kp,
                                   "vin": self.vin, "motor": self.motor,
                                   "trajectory": self.trajectory}
        if self.arm_mass:
            head["arm_mass"] = self.arm_mass
        return {**head, "entries": entries}


def _num(src: str, data: dict[str, object], key: str) -> float:
    v = data.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ConfigError(f"{src}: {key}: expected a number, got {v!r}")
    try:
        return float(v)
    except OverflowError:           # a JSON integer of hundreds of digits
        return math.inf if v > 0 else -math.inf


def checked_log(log: PendulumLog, *, law: str | None = None) -> PendulumLog:
    """``log`` if it keeps every rule of ``robot.servo.log_rules`` (``law``: the firmware
    law it will be replayed with, for the range of its ``kp``; None: any); ConfigError
    of one line naming the log and the field otherwise."""
    where = log.source
    rules.rig(f"{where}: ", mass=log.mass, length=log.length, arm_mass=log.arm_mass)
    rules.supply(f"{where}: vin", log.vin)
    rules.register_value(f"{where}: kp", log.kp, law=law)
    rules.times(where, log.t)
    for name, values in (("goal_position", log.goal), ("position", log.position)):
        rules.samples(where, name, values, most=rules.MAX_ANGLE, unit="rad")
    rules.samples(where, "speed", log.speed, most=rules.MAX_SPEED, unit="rad/s")
    for name, values in (("load", log.load), ("input_volts", log.input_volts),
                         ("temp", log.temp)):
        rules.samples(where, name, values)
    return log


def parse_log(data: object, *, source: str, law: str | None = None) -> PendulumLog:
    """A log from its decoded JSON, checked (``checked_log``; ConfigError, one line,
    naming what is wrong)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: expected a JSON object with 'entries'")
    entries = data.get("entries")
    if not isinstance(entries, list) or len(entries) < 2:
        raise ConfigError(f"{source}: entries: expected a list of at least 2 samples")
    cols: dict[str, list[float]] = {k: [] for k in ("timestamp", *_SERIES)}
    enable: list[bool] = []
    for i, e in enumerate(entries):
        if not isinstance(e, dict):
            raise ConfigError(f"{source}: entries[{i}]: expected an object")
        for k, col in cols.items():
            if k in ("load", "input_volts", "temp", "speed") and k not in e:
                col.append(0.0)
                continue
            col.append(_num(f"{source}: entries[{i}]", e, k))
        enable.append(rules.flag(f"{source}: entries[{i}].torque_enable",
                                 e.get("torque_enable", True)))
    t = np.array(cols["timestamp"])
    rules.times(source, t)          # before t - t[0] turns an infinite stamp into NaN
    kp = rules.register_value(f"{source}: kp", _num(source, data, "kp"), law=law)
    motor, trajectory = data.get("motor", ""), data.get("trajectory", "")
    return checked_log(PendulumLog(
        source=source, mass=_num(source, data, "mass"), length=_num(source, data, "length"),
        kp=kp, vin=_num(source, data, "vin"), motor=str(motor),
        trajectory=str(trajectory), t=t - t[0], goal=np.array(cols["goal_position"]),
        position=np.array(cols["position"]), speed=np.array(cols["speed"]),
        torque_enable=np.array(enable), load=np.array(cols["load"]),
        input_volts=np.array(cols["input_volts"]), temp=np.array(cols["temp"]),
        arm_mass=_num(source, data, "arm_mass") if "arm_mass" in data else 0.0), law=law)


def read_log(path: str | Path, *, law: str | None = None) -> PendulumLog:
    """Read a ``.json`` or ``.json.gz`` pendulum log, checked (``parse_log``)."""
    p = Path(path)
    try:
        raw = p.read_bytes()
        text = gzip.decompress(raw) if p.suffix == ".gz" else raw
        data = json.loads(text)
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except (OSError, EOFError, gzip.BadGzipFile) as e:
        raise ConfigError(f"{p}: cannot read: {e}") from e
    except (ValueError, RecursionError) as e:   # JSON, UTF-8, a 5000-digit number, nesting
        raise ConfigError(f"{p}: not a JSON pendulum log: {e}") from e
    return parse_log(data, source=str(p), law=law)


def write_log(log: PendulumLog, path: str | Path) -> Path:
    """Write ``log`` as JSON (gzip-compressed when ``path`` ends in .gz), whole or not at
    all (a temporary name, renamed); a log that breaks a rule (``checked_log``) is refused
    before anything is written, so every log written can be read."""
    p = Path(path)
    text = json.dumps(checked_log(log).to_json(), separators=(",", ":")).encode()
    write_bytes(p, gzip.compress(text, mtime=0) if p.suffix == ".gz" else text)
    return p


def split_logs(paths: list[Path], share: float) -> tuple[list[Path], list[Path]]:
    """(train, held out): sorted by name, every n-th log held out (n = round(1 / share)),
    the held-out index shifting by one each round of n, so a set recorded as gains x
    trajectories holds out a different trajectory at each gain. share 0: none held out."""
    ordered = sorted(paths, key=lambda p: p.name)
    if share <= 0:
        return ordered, []
    n = max(2, round(1 / share))
    held = [p for i, p in enumerate(ordered) if i % n == (i // n) % n]
    return [p for p in ordered if p not in held], held
