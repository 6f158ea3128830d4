"""The robot file's gain tables: ``[bus.gains]`` (every servo on the bus) and
``[joints.<name>.gains]`` (one servo), register values named as in robot/servo/gains.py.

Every problem is one ConfigError line naming the file and the field path: an unknown name
lists the valid ones with their ranges; a value outside the register's range names it; a
``[bus.gains]`` name that one joint's own ``model`` does not have names that joint.
"""

from __future__ import annotations

from collections.abc import Mapping

from robot.config.toml_io import Range, TomlTable, TomlValue, number, table
from robot.errors import ConfigError
from robot.servo.gains import GAIN_SETS, describe
from robot.servo.models import ServoModel

#: The sub-table's key inside ``[bus]`` and ``[joints.<name>]``.
KEY = "gains"


def split_gains(src: str, path: str, data: TomlValue) -> tuple[TomlTable, TomlValue]:
    """``data`` (checked to be a table) without its ``gains`` sub-table, and that sub-table
    (``{}`` when absent)."""
    tab = table(src, path, data)
    rest = {k: v for k, v in tab.items() if k != KEY}
    return rest, tab.get(KEY, {})


def parse_gains(src: str, path: str, data: TomlValue, servo: ServoModel) -> dict[str, int]:
    """The gains at ``path`` (e.g. ``bus.gains``) checked against ``servo``'s gain set:
    integer register values inside each register's range."""
    gains = table(src, path, data)
    return {name: _value(src, f"{path}.{name}", name, v, servo) for name, v in gains.items()}


def check_fits(src: str, gains: Mapping[str, int], servo: ServoModel, joint: str) -> None:
    """Every ``[bus.gains]`` entry is valid for joint ``joint``'s own servo model too."""
    for name, v in gains.items():
        _value(src, f"bus.gains.{name}", name, v, servo, who=f"joints.{joint}'s servo ")


def _value(src: str, path: str, name: str, value: TomlValue, servo: ServoModel, *,
           who: str = "") -> int:
    gain_set = GAIN_SETS[servo.gain_set]
    gain = gain_set.gains.get(name)
    if gain is None:
        raise ConfigError(f"{src}: {path}: not a gain of {who}{servo.name} (gain set "
                          f"{gain_set.name}); valid: {describe(gain_set.name)}")
    where = f"{path} ({who}{servo.name})" if who else path
    return number(src, where, value, Range(gain.lo, gain.hi), integer=True)
