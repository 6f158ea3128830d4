"""A robot file with extra joints for the tests: the default robot with a head pan and
tilt, a jaw and a tail (servo ids 19-22), each held at a fixed angle by the gait."""

from __future__ import annotations

from pathlib import Path

from robot.config.bundled import DEFAULT_ROBOT

EXTRAS = {"head_pan": (19, 0.2), "head_tilt": (20, -0.3), "jaw": (21, 0.1),
          "tail": (22, 0.25)}


def write_extra_robot(folder: Path) -> Path:
    text = DEFAULT_ROBOT.read_text()
    head, rest = text.split("[rest]", 1)
    head = head.replace('name = "biped18-dynamixel"', 'name = "biped22-extras"', 1)
    for name, (sid, angle) in EXTRAS.items():
        head += (f"[joints.{name}]\nservo_id = {sid}\nsign = 1\nzero_ticks = 2048\n"
                 f"min_rad = -0.8\nmax_rad = 0.8\nmax_speed_rad_s = 4.0\n"
                 f"fixed_rad = {angle}\n\n")
    out = folder / "biped22-extras.toml"
    out.write_text(head + "[rest]" + rest)
    return out
