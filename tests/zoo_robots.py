"""Robot files for the servos of issue 21, made from the bundled ones for tests: the
bundled biped with another servo model (and bus kind), a patient reply timeout, no
``[bus.gains]`` (those name the bundled model's registers)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import NamedTuple

from bus_harness import PATIENT_TIMEOUT_MS

from robot.config.bundled import ROBOTS_DIR

#: Reply timeout [ms] for the emulator on a shared machine: no zoo test makes a servo silent.
PATIENT_MS = PATIENT_TIMEOUT_MS


class Variant(NamedTuple):
    """One protocol variant and table layout: the emulator protocol, the bundled robot it
    starts from (1024-step models from the AX humanoid, 4096-step ones from the XL430
    biped), the servo model; goal: Goal Position (address, size) as the model's manual
    prints it; dual: the hip roll / pitch axes on 2XL430-W250 cases."""

    protocol: str
    base: str
    model: str
    goal: tuple[int, int]
    dual: bool = False


#: One robot per protocol variant and table layout the issue adds.
VARIANTS: dict[str, Variant] = {
    "dynamixel_xl320": Variant("dynamixel", "biped18-ax12", "XL-320", (30, 2)),
    "feetech_scs": Variant("feetech", "biped18-ax12", "SCS0009", (42, 2)),
    "dynamixel_xm": Variant("dynamixel", "biped18-dynamixel", "XM430-W350", (116, 4)),
    "dynamixel_xl330": Variant("dynamixel", "biped18-dynamixel", "XL330-M288", (116, 4)),
    "dynamixel_mx2": Variant("dynamixel", "biped18-dynamixel", "MX-28(2.0)", (116, 4)),
    "dynamixel_mx28_1": Variant("dynamixel1", "biped18-dynamixel", "MX-28", (30, 2)),
    "dynamixel_mx64_1": Variant("dynamixel1", "biped18-dynamixel", "MX-64", (30, 2)),
    "dynamixel_mx106_1": Variant("dynamixel1", "biped18-dynamixel", "MX-106", (30, 2)),
    "dynamixel_2xl": Variant("dynamixel", "biped18-dynamixel", "XL430-W250", (116, 4),
                             dual=True),
}
DUAL_CASES = {"r_hip": ("r_hip_roll", "r_hip_pitch"), "l_hip": ("l_hip_roll", "l_hip_pitch")}
DUAL_MODEL = "2XL430-W250"


def robot_file(v: Variant, tmp: Path, name: str) -> Path:
    """Write the variant's robot file into ``tmp``; return its path."""
    text = (ROBOTS_DIR / f"{v.base}.toml").read_text()
    text = re.sub(r'^name = ".*"$', f'name = "{name}"', text, count=1, flags=re.M)
    text = re.sub(r'^kind = ".*"$', f'kind = "{v.protocol}"', text, count=1, flags=re.M)
    text = re.sub(r'^model = ".*"$', f'model = "{v.model}"', text, count=1, flags=re.M)
    text = re.sub(r"^timeout_ms = .*$", f"timeout_ms = {PATIENT_MS}", text, count=1,
                  flags=re.M)
    text = re.sub(r"^\[bus\.gains\].*?(?=^\[)", "", text, count=1, flags=re.M | re.S)
    if v.dual:
        for case, joints in DUAL_CASES.items():
            for j in joints:
                text = text.replace(f"[joints.{j}]\n",
                                    f'[joints.{j}]\nmodel = "{DUAL_MODEL}"\ncase = "{case}"\n')
    path = tmp / f"{name}.toml"
    path.write_text(text)
    return path
