"""One emulated LX bus servo (LX-16A, LX-224, LX-224HV): its state and its motion.

The LX servo has no control table, so its state is named fields (``snapshot()`` keys,
shared names with the register families where the meaning is the same: ``id``,
``torque_enable``, ``goal_position``, ``present_position``). Behaviour, from the manual
(``sim.emulator.lx_commands``) where it says, else marked as an assumption:

- MOVE_TIME_WRITE: from where the horn is to the goal at a uniform speed, arriving after
  the move time, never faster than the model's no-load speed; the goal is clamped to the
  angle limits (assumption: the manual only says they limit the rotation).
- Unloaded (LOAD_OR_UNLOAD 0, the power-on state) the horn is free: a move is stored
  (MOVE_TIME_READ returns it) but nothing moves; loading holds the horn where it is
  (assumption: the manual does not say what a load does to a stored goal).
- Offset (-125..125 steps of 0.24 deg): goals and positions are relative to it; adjusting
  it moves the horn at once (manual, command 17). Kept over power-off only once written.
- Faults (``conditions``): "overheating" reads a temperature above the limit and unloads
  until it ends, then loads again (manual, command 24); "voltage" reads an input voltage
  above the maximum and unloads (assumption: stays unloaded after it ends); "overload"
  (locked rotor) stops the horn and changes nothing on the wire.
"""

from __future__ import annotations

from sim.emulator.lx_commands import (
    BAUD,
    MOVE_TIME_MAX_MS,
    POSITION_MAX,
    TEMP_LIMIT_FACTORY,
    VIN_RANGE_MV,
)
from sim.emulator.servo import ServoSpec
from sim.emulator.servo_models import MODELS

#: Input voltage each model reads [mV]: its nominal supply (LX-16A / LX-224 7.4 V on two
#: Li-ion cells, LX-224HV 11.1 V on three).
SUPPLY_MV: dict[str, int] = {"LX-16A": 7400, "LX-224": 7400, "LX-224HV": 11100}
#: Temperature of a servo at rest [degC] (no thermal model).
ROOM_C = 30
#: EEPROM-kept fields (the manual: "saved when powered down").
KEPT = ("id", "saved_offset", "min_angle_limit", "max_angle_limit", "min_vin_mv",
        "max_vin_mv", "temperature_limit", "led_ctrl", "led_error")


class LxServo:
    """State and a constant-speed move model for one LX servo; ``update`` brings it to a
    time [s, time.monotonic()], as the chain does before every packet."""

    family = "lx"

    def __init__(self, spec: ServoSpec, now: float) -> None:
        self.spec = spec
        self.model = MODELS[spec.model]
        self.conditions: set[str] = set()
        self.stuck = False
        self.speed = self.model.no_load_speed * self.model.ticks_per_rad   # steps/s
        self.f: dict[str, int] = {
            "id": spec.servo_id, "saved_offset": 0, "angle_offset": 0,
            # a chain built from a robot is set up: the joint limits (factory 0..1000)
            "min_angle_limit": max(0, spec.min_ticks),
            "max_angle_limit": min(POSITION_MAX, spec.max_ticks),
            "min_vin_mv": VIN_RANGE_MV[0], "max_vin_mv": VIN_RANGE_MV[1],
            "temperature_limit": TEMP_LIMIT_FACTORY, "led_ctrl": 0, "led_error": 7,
            "torque_enable": 0, "goal_position": spec.zero_ticks, "move_time_ms": 0,
            "wait_position": spec.zero_ticks, "wait_time_ms": 0, "motor_mode": 0,
            "motor_speed": 0, "present_voltage_mv": round(self.model_voltage_mv()),
            "present_temperature": ROOM_C,
        }
        self._horn = float(spec.zero_ticks)     # where the horn is, without the offset
        self._from, self._t0, self._dur = self._horn, now, 0.0
        self._t = now
        self.heard = now
        self._saved = {k: self.f[k] for k in KEPT}
        self._overheated = False

    def model_voltage_mv(self) -> float:
        return float(SUPPLY_MV[self.model.name])

    # ------------------------------------------------------------------ identity
    @property
    def servo_id(self) -> int:
        return self.f["id"]

    @property
    def baud(self) -> int:
        return BAUD

    def hear(self, now: float) -> None:
        self.heard = now

    # ------------------------------------------------------------------ motion
    def _target(self) -> float:
        return float(self.f["goal_position"] + self.f["angle_offset"])

    def update(self, now: float, *, quiet_until: float = float("inf")) -> None:
        """Advance the move and the fault conditions to ``now`` [s]; no watchdog exists."""
        self._faults()
        dt = max(0.0, now - self._t)
        self._t = now
        if not self.f["torque_enable"] or self.stuck or "overload" in self.conditions:
            self._from, self._t0, self._dur = self._horn, now, 0.0
            return
        target = self._target()
        if self._dur > 0:               # a timed move: uniform speed, there at t0 + dur
            share = min(1.0, (now - self._t0) / self._dur)
            self._horn = self._from + (target - self._from) * share
            if share >= 1.0:
                self._dur = 0.0
        else:                           # holding: back to the target at the top speed
            step = self.speed * dt
            self._horn = min(target, self._horn + step) if target > self._horn else \
                max(target, self._horn - step)

    def _faults(self) -> None:
        hot, volt = "overheating" in self.conditions, "voltage" in self.conditions
        limit = self.f["temperature_limit"]
        self.f["present_temperature"] = limit + 5 if hot else ROOM_C
        self.f["present_voltage_mv"] = (self.f["max_vin_mv"] + 500 if volt
                                        else round(self.model_voltage_mv()))
        if hot or volt:
            self.f["torque_enable"] = 0
        elif self._overheated:
            self.f["torque_enable"] = 1        # cooled below the limit: loads again
        self._overheated = hot

    def move(self, position: int, time_ms: int) -> None:
        """MOVE_TIME_WRITE (or MOVE_START of a stored one): go there in ``time_ms``."""
        lo, hi = self.f["min_angle_limit"], self.f["max_angle_limit"]
        self.f["goal_position"] = max(lo, min(hi, position))
        self.f["move_time_ms"] = min(max(time_ms, 0), MOVE_TIME_MAX_MS)
        self._from, self._t0 = self._horn, self._t
        fastest = abs(self._target() - self._horn) / self.speed
        self._dur = max(self.f["move_time_ms"] / 1000.0, fastest)

    def stop(self) -> None:
        """MOVE_STOP: stay where the horn is."""
        self.f["goal_position"] = round(self._horn) - self.f["angle_offset"]
        self._from, self._t0, self._dur = self._horn, self._t, 0.0

    def load(self, on: bool) -> None:
        """LOAD_OR_UNLOAD: torque on holds the horn where it is."""
        if on and not self.f["torque_enable"]:
            self.stop()
        self.f["torque_enable"] = int(on)

    def adjust_offset(self, offset: int) -> None:
        """ANGLE_OFFSET_ADJUST: positions shift; a loaded horn moves at once."""
        self.f["angle_offset"] = offset
        self._from, self._t0, self._dur = self._horn, self._t, 0.0

    @property
    def position(self) -> int:
        """POS_READ: where the horn is, relative to the offset (may be below 0)."""
        return round(self._horn) - self.f["angle_offset"]

    # ------------------------------------------------------------------ chain interface
    def snapshot(self) -> dict[str, int]:
        return {**self.f, "present_position": self.position}

    def set(self, name: str, value: int) -> None:
        """Back door: ``present_position`` moves the horn (by hand), anything else is stored."""
        if name == "present_position":
            self._horn = float(value + self.f["angle_offset"])
            self._from, self._dur = self._horn, 0.0
        elif name in self.f:
            self.f[name] = int(value)
        else:
            raise KeyError(f"no LX servo field {name!r}; valid: present_position, "
                           f"{', '.join(self.f)}")

    def keep(self) -> None:
        """Save what the manual keeps over power-off (after a write of a kept value)."""
        self._saved = {k: self.f[k] for k in KEPT}

    def power_off(self, now: float) -> None:
        self.update(now)
        self.f["torque_enable"] = 0

    def power_on(self, now: float) -> None:
        """Kept fields as saved; the rest at power-on values (unloaded, position mode)."""
        self.update(now)
        self.f.update(self._saved)
        self.f.update(torque_enable=0, motor_mode=0, motor_speed=0,
                      angle_offset=self.f["saved_offset"])
        self.stop()
        self._t = self.heard = now
