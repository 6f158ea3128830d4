"""What one servo model is, as data (``ServoModel``): the facts a datasheet and a control
table give about it. The models themselves are in ``models_dynamixel``, ``models_feetech``
and ``models_lx``; ``robot.servo.models`` gathers them with the families' baud codes.

This module imports nothing of the project.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import NamedTuple

RPM = 2.0 * math.pi / 60.0      # rad/s per rev/min
KGCM = 9.80665e-2               # N m per kg cm


def per_60deg(seconds: float) -> float:
    """A hobby datasheet's "s/60 deg" as a speed [rad/s]."""
    return (math.pi / 3) / seconds


class ServoModel(NamedTuple):
    """Datasheet facts about one servo model.

    number: model number as reported by ping / the model_number register
    family: its control-table family (a key of ``robot.bus.tables.TABLES``): which table,
        error bits and baud codes it has
    resolution: number of positions (goal/present ticks run 0..resolution-1)
    stall_torque: stall torque at the nominal voltage [N m]
    no_load_speed: no-load speed at the nominal voltage [rad/s]
    mass: [kg] (one axis of a dual-axis servo: half the case)
    nominal_voltage: [V]
    """

    name: str
    number: int
    family: str
    resolution: int
    stall_torque: float
    no_load_speed: float
    mass: float
    nominal_voltage: float
    #: angle the ``resolution`` positions span [deg]: 360 for a full turn, 300 for the AX
    #: series (1024 ticks over 300 deg, i.e. an effective 1228.8 ticks per turn)
    span_deg: float = 360.0
    #: key of ``robot.servo.gains.GAIN_SETS``: the gain registers this servo's firmware has
    gain_set: str = ""
    #: the gains as the servo leaves the factory (register values; every gain of the set)
    factory_gains: Mapping[str, int] = MappingProxyType({})
    #: ids one case answers at: 2 for the dual-axis 2XL430-W250 / 2XC430-W250 (two motors,
    #: two control tables, one shared baud rate), else 1
    axes: int = 1
    #: the baud rate it ships at [bit/s]; 0: its family's (``models.FACTORY_BAUD``)
    factory_baud: int = 0
    #: False where no vendor page at hand prints the model number (scan still names it;
    #: setup-motors then accepts a servo of the family that reports an unknown number)
    number_verified: bool = True

    @property
    def ticks_per_rad(self) -> float:
        """Ticks per radian of output shaft."""
        return self.resolution / math.radians(self.span_deg)
