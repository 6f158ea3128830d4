"""`biped walk --switch T:PRESET`: switch to another gait preset at gait time T, blended
live (robot.run.switching, robot.gait.blend; docs/gait.md "Switching presets live")."""

from __future__ import annotations

import argparse
import logging

from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.run.switching import PresetSwitch

log = logging.getLogger(__name__)

#: Latest gait time a switch may name [s] (as --push).
SWITCH_MAX_S = 1e6


def switch_spec(text: str) -> tuple[float, str]:
    """An argparse type: ``T:PRESET`` → (gait time [s], preset name or path)."""
    t_text, _, name = text.partition(":")
    try:
        t = float(t_text)
    except ValueError:
        t = float("nan")
    if not (0.0 <= t <= SWITCH_MAX_S and name):      # false for nan
        raise argparse.ArgumentTypeError(
            f"expected T:PRESET with T in [0, {SWITCH_MAX_S:g}] s and a gait preset "
            f"(e.g. 8:jog), got {text!r}")
    return t, name


def add_switch_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument("--switch", type=switch_spec, action="append", default=[],
                   metavar="T:PRESET",
                   help="at gait time T [s] switch to gait PRESET, blended live over about "
                        "a second (repeatable; the --set items stay with the first gait)")


def switches_from(args: argparse.Namespace, robot: RobotConfig) -> tuple[PresetSwitch, ...]:
    """The ``--switch`` presets loaded for ``robot`` (its balance gains where a preset
    names none); a preset that does not load: ConfigError naming the option."""
    out = []
    for t, name in args.switch:
        try:
            gait = load_gait(name)
        except ConfigError as e:
            raise ConfigError(f"--switch {t:g}:{name}: {str(e).removeprefix('--gait: ')}") from e
        if gait.warning:
            log.warning("--switch %g:%s: gait %r: %s", t, name, gait.name, gait.warning)
        out.append(PresetSwitch(t, gait.name, gait.for_robot(robot)))
    return tuple(out)
