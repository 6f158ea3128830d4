"""What an LX servo reports besides its position, gathered one value per read-back.

The LX protocol has no status packet: temperature, voltage and the load state are three
separate read commands per servo, and no command reports a fault (the LED is the only
alarm, manual Table 3). ``LxStatus`` hands out one value to read per ``read_state`` in
turn (each servo's limits once, then temperature, voltage and load state round-robin) and
derives the faults the servo acts on from what it read: "overheating" at or above its
temperature limit, "voltage" outside its input-voltage limits (the manual: the servo then
unloads itself). A locked rotor is not visible on the wire; the streamer's follow check
sees a servo that does not follow.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from robot.bus.base import ServoState

#: The values read in turn, after the limits (names of port.LX_VALUES).
CYCLE = ("present_temperature", "present_voltage_mv", "torque_enable")
LIMITS = ("temperature_limit", "min_voltage_limit_mv")   # the second also brings the max


@dataclass
class Known:
    """The last value read of each kind for one servo (None: not read yet)."""

    temperature: float | None = None       # degC
    voltage: float | None = None           # V
    loaded: bool | None = None
    temperature_limit: float | None = None  # degC
    voltage_limits: tuple[float, float] | None = None  # V


class LxStatus:
    """One servo value to read per read-back, and the ServoState built from all of them."""

    def __init__(self) -> None:
        self.known: dict[int, Known] = {}
        self._turn = 0

    def next_query(self, ids: Sequence[int]) -> tuple[int, str] | None:
        """(servo id, value name) to read on this read-back; None when ``ids`` is empty.
        A servo's limits come first; then temperature, voltage, load state in turn."""
        if not ids:
            return None
        for sid in ids:
            k = self.known.setdefault(sid, Known())
            if k.temperature_limit is None:
                return sid, LIMITS[0]
            if k.voltage_limits is None:
                return sid, LIMITS[1]
        sid = ids[self._turn % len(ids)]
        name = CYCLE[(self._turn // len(ids)) % len(CYCLE)]
        self._turn += 1
        return sid, name

    def record(self, sid: int, name: str, values: Sequence[int]) -> None:
        """Store what was read: ``values`` are the value (and for the voltage limits, the
        max after the min) in the protocol's units (degC, mV, 0/1)."""
        k = self.known.setdefault(sid, Known())
        if name == "present_temperature":
            k.temperature = float(values[0])
        elif name == "present_voltage_mv":
            k.voltage = values[0] / 1000.0
        elif name == "torque_enable":
            k.loaded = bool(values[0])
        elif name == "temperature_limit":
            k.temperature_limit = float(values[0])
        elif name == "min_voltage_limit_mv":
            k.voltage_limits = (values[0] / 1000.0, values[1] / 1000.0)

    def state(self, sid: int, position: int) -> ServoState:
        """``sid``'s state: the position just read and the latest of everything else."""
        k = self.known.get(sid, Known())
        errors = set()
        if k.temperature is not None and k.temperature_limit is not None \
                and k.temperature >= k.temperature_limit:
            errors.add("overheating")
        if k.voltage is not None and k.voltage_limits is not None \
                and not k.voltage_limits[0] <= k.voltage <= k.voltage_limits[1]:
            errors.add("voltage")
        return ServoState(id=sid, position=position, temperature=k.temperature,
                          voltage=k.voltage, errors=frozenset(errors))
