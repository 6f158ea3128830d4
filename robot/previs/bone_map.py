"""Which bone drives which robot joint, about which axis: by name for the skeleton
``biped export`` writes (no file needed), or from a small mapping file for a character
rigged elsewhere.

```toml
# MAP.toml: one table per robot joint that the animation drives
up = "+z"                  # optional: the rig's up axis (default: found from the rest pose)
[joints.r_knee]
bone = "shin.R"            # the bone's name in the file
axis = "y"                 # robot axis of the rotation: x forward, y left, z up
sign = 1                   # -1 if the rig turns the other way (optional, default 1)
offset = 0.0               # [rad] added after the sign (optional): the rig's rest vs the robot's zero
```

Joints on one bone are decomposed in the order the file lists them (a hip: yaw z, roll x,
pitch y, as the robot composes them); the axes a bone does not use are taken out first.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from robot.config.robot import RobotConfig
from robot.config.toml_io import TomlValue, number, read_toml, show, table
from robot.errors import ConfigError
from robot.previs.bvh import skeleton
from robot.previs.rig import UPS


@dataclass(frozen=True)
class JointMap:
    """Robot joint ``joint`` = ``sign`` x the rotation of ``bone`` about robot ``axis``
    [rad] + ``offset`` [rad]."""

    joint: str
    bone: str
    axis: str
    sign: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class BoneMap:
    """joints: every mapped joint, in decomposition order per bone; up: the rig's up axis
    (None: detect it)."""

    joints: tuple[JointMap, ...]
    up: str | None = None
    source: str = "by name"

    def bones(self) -> dict[str, tuple[str, tuple[JointMap | None, ...]]]:
        """bone → (Euler order over all three axes, the joint on each axis or None)."""
        out: dict[str, list[JointMap]] = {}
        for m in self.joints:
            out.setdefault(m.bone, []).append(m)
        result = {}
        for bone, maps in out.items():
            used = [m.axis for m in maps]
            free = [a for a in "zxy" if a not in used]
            order = "".join(free) + "".join(used)
            result[bone] = (order, (None,) * len(free) + tuple(maps))
        return result


def by_name(robot: RobotConfig) -> BoneMap:
    """The map of the skeleton ``biped export`` writes for ``robot`` (robot/previs/bvh.py)."""
    maps = [JointMap(joint, b.name, axis, b.sign(k)) for b in skeleton(robot)
            for k, (axis, joint) in enumerate(b.axes) if joint is not None]
    return BoneMap(tuple(maps))


def _joint(src: str, name: str, data: TomlValue, robot: RobotConfig) -> JointMap:
    if name not in robot.joint_names:
        raise ConfigError(f"{src}: joints.{name}: not a joint of {robot.name}; valid: "
                          f"{', '.join(robot.joint_names)}")
    tab = table(src, f"joints.{name}", data)
    unknown = sorted(set(tab) - {"bone", "axis", "sign", "offset"})
    if unknown:
        raise ConfigError(f"{src}: joints.{name}.{unknown[0]}: unknown key; valid: bone, "
                          "axis, sign, offset")
    bone = tab.get("bone")
    if not isinstance(bone, str) or not bone:
        raise ConfigError(f"{src}: joints.{name}.bone: expected the bone's name, got "
                          f"{show(bone)}")
    axis = tab.get("axis")
    if axis not in ("x", "y", "z"):
        raise ConfigError(f"{src}: joints.{name}.axis: expected x, y or z (robot axes: x "
                          f"forward, y left, z up), got {show(axis)}")
    sign = tab.get("sign", 1)
    if sign not in (1, -1) or isinstance(sign, bool):
        raise ConfigError(f"{src}: joints.{name}.sign: expected 1 or -1, got {show(sign)}")
    offset = number(src, f"joints.{name}.offset", tab.get("offset", 0.0))
    return JointMap(name, bone, str(axis), -1.0 if sign == -1 else 1.0, offset)


def load_map(path: str | Path, robot: RobotConfig) -> BoneMap:
    """A mapping file checked against ``robot`` (ConfigError, one line, on any problem)."""
    p = Path(path)
    data: Mapping[str, TomlValue] = read_toml(p)
    src = str(p)
    unknown = sorted(set(data) - {"up", "joints"})
    if unknown:
        raise ConfigError(f"{src}: {unknown[0]}: unknown key; valid: up, joints")
    up = data.get("up")
    if up is not None and up not in UPS:
        raise ConfigError(f"{src}: up: expected one of {', '.join(UPS)}, got {show(up)}")
    joints = table(src, "joints", data.get("joints", {}))
    if not joints:
        raise ConfigError(f"{src}: joints: expected at least one [joints.NAME] table")
    maps = [_joint(src, name, value, robot) for name, value in joints.items()]
    seen: dict[tuple[str, str], str] = {}
    for m in maps:
        other = seen.setdefault((m.bone, m.axis), m.joint)
        if other != m.joint:
            raise ConfigError(f"{src}: joints.{m.joint}: bone {m.bone!r} axis {m.axis} is "
                              f"already joints.{other}'s")
    return BoneMap(tuple(maps), up if isinstance(up, str) else None, src)
