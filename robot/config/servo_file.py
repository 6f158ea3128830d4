"""Servo model files: a fitted ``robot.servo.physics.ServoPhysics`` as TOML, written by
``biped identify fit --out model.toml`` and named by a robot file for any joint
(``[bus] servo_file`` for every joint, ``[joints.<name>] servo_file`` for one).

```toml
model = "XL330-M288"          # the servo model (robot/servo/models.py) it describes
law = "dynamixel_x"           # robot/servo/firmware.py LAWS
nominal_voltage = 7.4         # [V]
kt = 0.31                     # every ServoPhysics number, SI units
...
[sources]                     # where each number came from
kt = "fitted on 12 logs ..."
[fit]                         # how the fit went (read by people, not by the sim)
train_error_rad = 0.041
```
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import fields
from functools import cache
from pathlib import Path

from robot.config.bundled import CONFIG_DIR
from robot.config.toml_io import number, read_toml, show, table
from robot.errors import ConfigError
from robot.servo.firmware import LAWS
from robot.servo.models import MODELS
from robot.servo.physics import ServoPhysics
from robot.servo.physics_table import PHYSICS

#: The identified models shipped with the package (``<model name>.toml``).
SERVOS_DIR = CONFIG_DIR / "servos"

_NUMBERS = [f.name for f in fields(ServoPhysics) if f.name not in ("name", "law", "sources")]


def parse_servo_file(data: Mapping[str, object], *, source: str) -> ServoPhysics:
    """A ServoPhysics from a model file's table (ConfigError, one line, on any problem)."""
    allowed = {"model", "law", "sources", "fit", *_NUMBERS}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ConfigError(f"{source}: {unknown[0]}: unknown key; valid: {', '.join(sorted(allowed))}")
    model = data.get("model")
    if model not in MODELS:
        raise ConfigError(f"{source}: model: expected one of {', '.join(MODELS)}, got {show(model)}")
    law = data.get("law")
    if law not in LAWS:
        raise ConfigError(f"{source}: law: expected one of {', '.join(LAWS)}, got {show(law)}")
    values: dict[str, float] = {}
    for name in _NUMBERS:
        if name in data:
            v = number(source, name, data[name])
            if v < 0 or (v == 0 and name in ("kt", "resistance", "nominal_voltage", "max_duty")):
                raise ConfigError(f"{source}: {name}: expected a positive number, got {show(v)}")
            values[name] = v
        elif name in ("kt", "resistance", "armature", "coulomb", "viscous", "nominal_voltage"):
            raise ConfigError(f"{source}: {name}: missing")
    sources = table(source, "sources", data.get("sources", {}))  # type: ignore[arg-type]
    return ServoPhysics(name=str(model), law=str(law), **values,  # type: ignore[arg-type]
                        sources={str(k): str(v) for k, v in sources.items()})


def load_servo_file(path: str | Path) -> ServoPhysics:
    """Read and validate a servo model file."""
    p = Path(path)
    return parse_servo_file(read_toml(p), source=str(p))


def _toml(value: object) -> str:
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return json.dumps(value) if isinstance(value, str) else repr(value)


def servo_file_text(physics: ServoPhysics, *, fit: Mapping[str, object] | None = None,
                    comment: str = "") -> str:
    """The TOML text of a model file for ``physics`` (``fit``: the [fit] table)."""
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"model = {_toml(physics.name)}", f"law = {_toml(physics.law)}"]
    lines += [f"{name} = {_toml(float(getattr(physics, name)))}" for name in _NUMBERS
              if math.isfinite(getattr(physics, name))]   # max_velocity inf: no limit
    lines += ["", "[sources]"]
    lines += [f"{k} = {_toml(v)}" for k, v in physics.sources.items()]
    if fit:
        lines += ["", "[fit]"] + [f"{k} = {_toml(v)}" for k, v in fit.items()]
    return "\n".join(lines) + "\n"


@cache
def physics_for(model: str) -> ServoPhysics:
    """A servo model's bundled physics: its identified file in SERVOS_DIR if one ships,
    else the table (robot/servo/physics_table.py)."""
    path = SERVOS_DIR / f"{model}.toml"
    return load_servo_file(path) if path.is_file() else PHYSICS[model]


def servo_files(src: str, bus_file: str | None,
                joints: Sequence[tuple[str, str | None, str]]) -> dict[str, ServoPhysics]:
    """The model files a robot file names (``[bus] servo_file``, ``[joints.X] servo_file``,
    relative to the robot file ``src``), read per joint name; ``joints``: (name, its
    servo_file, its servo model) each. Each file must describe the joint's servo model."""
    out: dict[str, ServoPhysics] = {}
    base = Path(src).parent
    for joint, own, model in joints:
        name = own or bus_file
        if name is None:
            continue
        where = f"joints.{joint}.servo_file" if own else "bus.servo_file"
        path = Path(name) if Path(name).is_absolute() else base / name
        try:
            physics = load_servo_file(path)
        except ConfigError as e:
            raise ConfigError(f"{src}: {where}: {e}") from e
        if physics.name != model:
            raise ConfigError(f"{src}: {where}: {path} describes a {physics.name}, but the "
                              f"joint's servo is a {model}")
        out[joint] = physics
    return out
