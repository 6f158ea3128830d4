"""An import (robot/config/model_import.py) as robot file text: the usual tables (bus, IMU,
geometry, joints, rest) and the model's body (``[model]``, robot/config/model_file.py).

The geometry is measured from the model and only scales the gait; the simulation, the
IK and ``biped mjcf`` use the model's own body.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from robot.config.model_file import _q, model_toml, num
from robot.config.model_import import Imported
from robot.servo.models import ServoModel

GEOMETRY_ORDER = ("hip_width", "thigh", "shin", "ankle_height", "foot_length", "foot_width",
                  "foot_forward", "torso_height", "torso_depth", "shoulder_width", "upper_arm",
                  "forearm")


def robot_file_text(imp: Imported, *, name: str, kind: str, servo: ServoModel, baud: int,
                    header: list[str], gains: Mapping[str, int] | None = None,
                    balance: Mapping[str, float] | None = None,
                    gait: Mapping[str, float] | None = None) -> str:
    """The robot file for ``imp`` (``header``: comment lines to open it with; ``gains``:
    ``[bus.gains]``; ``balance``: ``[balance]``; ``gait``: ``[gait]``; each joint's own
    gains: ``[joints.NAME.gains]``)."""
    out = [f"# {line}" if line else "#" for line in header]
    out += ["", f"name = {_q(name)}", "", "[bus]", f"kind = {_q(kind)}", f"model = {_q(servo.name)}",
            'port = "/dev/ttyUSB0"', f"baud = {baud}", "",
            *(["[bus.gains]  # written by the driver before torque on (docs/servos.md)",
               *(f"{k} = {v}" for k, v in gains.items()), ""] if gains else []),
            *(["[balance]  # this robot's balance gains (docs/gait.md)",
               *(f"{k} = {num(float(v))}" for k, v in balance.items()), ""] if balance else []),
            *(["[gait]  # what this robot's body needs, over any preset (docs/robots.md)",
               *(f"{k} = {num(float(v))}" for k, v in gait.items()), ""] if gait else []),
            "[imu]  # simulated at the torso's centre of mass (the model's \"imu\" frame); docs/imu.md",
            'kind = "sim"', "", "[geometry]  # measured from the model at the zero pose [m]; "
            "scales the gait (the sim and the IK use [model])"]
    g = imp.measured.lengths
    out += [f"{k} = {num(round(g[k], 6))}" for k in GEOMETRY_ORDER if k in g]
    out.append("")
    for j in imp.joints:
        out += [f"[joints.{j.name}]", f"model_joint = {_q(j.model_joint)}",
                f"model_sign = {j.model_sign}  # model angle = model_sign * angle + model_offset",
                f"model_offset = {num(round(j.model_offset, 9))}",
                f"servo_id = {j.servo_id}", f"sign = {j.sign}", f"zero_ticks = {j.zero_ticks}",
                f"min_rad = {num(math.ceil(j.min_rad * 1e6) / 1e6)}  # {j.limits_source}",
                f"max_rad = {num(math.floor(j.max_rad * 1e6) / 1e6)}",
                f"max_speed_rad_s = {num(j.max_speed_rad_s)}"]
        if j.fixed_rad is not None:
            out.append(f"fixed_rad = {num(round(j.fixed_rad, 6))}  # held while the gait runs")
        if j.gains:
            out += ["", f"[joints.{j.name}.gains]", *(f"{k} = {v}" for k, v in j.gains.items())]
        out.append("")
    rest = imp.rest
    if rest:
        out.append("[rest]  # the pose it returns to before torque off [rad]")
        out += [f"{k} = {num(v)}" for k, v in rest.items()]
        out.append("")
    out.append(model_toml(imp.model))
    return "\n".join(out) + "\n"
