"""The simulated servos behind ``sim.mujoco.bus.MujocoBus``: goals, setpoints, torque, load,
a thermal model and the overload flag, and an optional goal latency.

Servo model (arrays in ``robot.joints`` order):

- goal: the last goal written [rad], clamped to the joint limits; with ``latency_s`` > 0 a
  written goal takes effect ``latency_s`` of simulation time after the write (a queue
  keyed by sim time; torque on/off is not delayed);
- setpoint: the position actuator's reference [rad]. Before each physics step it moves
  toward the goal by at most ``max_speed_rad_s * step`` (like a servo's velocity
  profile). Once every torque-on setpoint has reached its goal the reference is constant
  and the bus runs the remaining physics steps of the tick in one ``mj_step`` call; this
  is the same simulation as slewing before every step (a settled slew changes nothing);
- torque off zeroes the actuator's gains (the joint goes limp); torque on restarts the
  setpoint from the present position, so the servo never snaps;
- load = actuator force / stall torque [%], signed in the servo's direction;
- temperature: a first-order thermal *model*, not a measurement: it relaxes toward
  ``AMBIENT_C + STALL_RISE_K * (force / stall torque)^2`` with time constant
  ``THERMAL_TAU_S``; errors: ``{"overload"}`` while the actuator has been saturated for more
  than ``OVERLOAD_AFTER_S``. Both are updated at the end of an ``advance`` (control tick)
  once ``ACCOUNT_PERIOD_S`` of sim time has passed since the last update, and before every
  read, with the force at that instant held over the elapsed span (not per physics step).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from robot.bus.base import ServoState
from robot.bus.servo_map import ServoMap

AMBIENT_C = 25.0  # [°C]
STALL_RISE_K = 60.0  # steady-state rise at continuous stall torque [K]
THERMAL_TAU_S = 180.0  # thermal time constant [s]
OVERLOAD_AFTER_S = 1.0  # saturated this long → "overload" [s]
SATURATED_RATIO = 0.999  # |force| / stall torque at or above this counts as saturated
#: Thermal and saturation bookkeeping period [s of sim time]: 2 % of OVERLOAD_AFTER_S.
ACCOUNT_PERIOD_S = 0.02
_TIME_EPS = 1e-9  # [s]
_OVERLOAD = frozenset({"overload"})
_NO_ERRORS: frozenset[str] = frozenset()

Floats = npt.NDArray[np.float64]


class SimServos:
    """Servo state for one simulated chain (see the module docstring).

    servo_map: the robot's tick conversion and limits; stall: stall torque per joint
    [N m]; q0: start position per joint [rad]; latency_s: goal latency [s]; max_speed: the
    setpoint slew per joint [rad/s] (default: the map's max_speed_rad_s).
    """

    def __init__(self, servo_map: ServoMap, stall: Floats, q0: Floats, *,
                 latency_s: float = 0.0, max_speed: Floats | None = None) -> None:
        n = len(servo_map.ids)
        self.map = servo_map
        self.stall = np.asarray(stall, float)
        self.latency_s = latency_s
        self.max_speed = servo_map.max_speed if max_speed is None else max_speed
        self.goal = np.array(q0, float)  # [rad]
        self.setpoint = self.goal.copy()  # [rad]
        self.enabled = np.zeros(n, dtype=bool)
        self.saturated_s = np.zeros(n)  # [s]
        self.temperature = np.full(n, AMBIENT_C)  # [°C]
        self.settled = True  # every torque-on setpoint is at its goal
        self._ids = tuple(servo_map.ids)
        self._signed_tpr = servo_map.sign * servo_map.ticks_per_rad  # [ticks/rad]
        self._all = np.arange(n)
        self._pending: deque[tuple[float, npt.NDArray[np.intp], Floats]] = deque()
        self._decay_span = -1.0
        self._decay = 0.0
        self._vmax_dt = -1.0
        self._vmax = np.zeros(n)  # slew limit per step of _vmax_dt [rad]
        self._unaccounted_s = 0.0
        self._any_saturated = False

    # ------------------------------------------------------------------ goals

    def to_rad(self, goals: Mapping[int, int], idx: npt.NDArray[np.intp]) -> Floats:
        """Goal ticks (values of ``goals``, for joints ``idx``) → radians in the limits."""
        return self._rad(np.fromiter(goals.values(), float, len(idx)), idx)

    def _rad(self, q: Floats, idx: npt.NDArray[np.intp]) -> Floats:
        """Ticks ``q`` of joints ``idx`` → radians in the limits, in place."""
        sm = self.map
        if idx is self._all:
            zero, per_rad, lo, hi = sm.zero, self._signed_tpr, sm.q_min, sm.q_max
        else:
            zero, per_rad = sm.zero[idx], self._signed_tpr[idx]
            lo, hi = sm.q_min[idx], sm.q_max[idx]
        # (t - zero) / (sign * ticks_per_rad): bit-identical to * sign / ticks_per_rad.
        q -= zero
        q /= per_rad
        np.maximum(q, lo, out=q)
        return np.minimum(q, hi, out=q)

    def write_ticks(self, ticks: Floats, now: float) -> None:
        """Goal ticks of every joint in joint order (whole numbers as floats; the array is
        used up), written at sim time ``now`` [s]: ``write`` of their radians."""
        self.write(self._all, self._rad(ticks, self._all), now)

    def index_all(self, goals: Mapping[int, int]) -> npt.NDArray[np.intp] | None:
        """All joints' indices if ``goals`` names every servo in joint order, else None."""
        return self._all if tuple(goals) == self._ids else None

    def write(self, idx: npt.NDArray[np.intp], q: Floats, now: float) -> None:
        """Goal ``q`` [rad] for joints ``idx``, written at sim time ``now`` [s]."""
        if self.latency_s > 0.0:
            self._pending.append((now + self.latency_s, idx, q))
        else:
            self._set_goal(idx, q)

    def _set_goal(self, idx: npt.NDArray[np.intp], q: Floats) -> None:
        if idx is self._all:
            self.goal = q
        else:
            self.goal[idx] = q
        self.settled = False

    @property
    def pending(self) -> bool:
        """Delayed goals are waiting (``latency_s`` > 0)."""
        return bool(self._pending)

    def next_due(self) -> float:
        """Sim time [s] at which the next delayed goal takes effect (inf if none)."""
        return self._pending[0][0] if self._pending else math.inf

    def release_due(self, now: float) -> None:
        """Apply every delayed goal due at or before ``now`` [s], oldest first."""
        while self._pending and self._pending[0][0] <= now + _TIME_EPS:
            _, idx, q = self._pending.popleft()
            self._set_goal(idx, q)

    # ------------------------------------------------------------------ setpoints

    def slew(self, dt: float) -> Floats:
        """Move each setpoint toward its goal by at most max_speed * ``dt`` [s]; update
        ``settled``; return the setpoints [rad]."""
        if dt != self._vmax_dt:
            self._vmax_dt, self._vmax = dt, self.max_speed * dt
        vmax = self._vmax
        error = self.goal - self.setpoint
        within = np.abs(error) <= vmax
        if np.logical_and.reduce(within):    # the usual tick: every setpoint reaches its goal
            self.setpoint = self.goal.copy()
            self.settled = True
            return self.setpoint
        self.setpoint = np.where(within, self.goal, self.setpoint + np.sign(error) * vmax)
        self.settled = bool(np.logical_and.reduce((self.setpoint == self.goal) | ~self.enabled))
        return self.setpoint

    def set_torque(self, idx: list[int], enabled: bool, present: Floats) -> None:
        """Torque on/off for joints ``idx``; turning on restarts the setpoint from the
        ``present`` positions [rad] (all joints)."""
        if enabled:
            off = [i for i in idx if not self.enabled[i]]
            self.setpoint[off] = present[off]
        self.enabled[idx] = enabled
        self.settled = False

    # ------------------------------------------------------------------ thermal, load

    def add_time(self, span: float) -> bool:
        """``span`` [s] of simulation passed: True once ACCOUNT_PERIOD_S has accumulated
        and the bookkeeping is due (then ``flush`` with the actuators' force now)."""
        self._unaccounted_s += span
        return self._unaccounted_s >= ACCOUNT_PERIOD_S - _TIME_EPS

    def flush(self, force: Floats) -> None:
        """Account the time elapsed since the last bookkeeping at ``force`` [N m]."""
        span, self._unaccounted_s = self._unaccounted_s, 0.0
        self.account(force, span)

    def account(self, force: Floats, span: float) -> None:
        """Saturation time and temperature after ``span`` [s] at actuator ``force`` [N m]."""
        if span <= 0.0:
            return
        ratio = np.abs(force)
        ratio /= self.stall
        if np.maximum.reduce(ratio) >= SATURATED_RATIO:
            saturated = self.enabled & (ratio >= SATURATED_RATIO)
            self.saturated_s = np.where(saturated, self.saturated_s + span, 0.0)
            self._any_saturated = bool(np.logical_or.reduce(self.saturated_s != 0.0))
        elif self._any_saturated:
            self.saturated_s.fill(0.0)
            self._any_saturated = False
        if span != self._decay_span:
            self._decay_span, self._decay = span, -math.expm1(-span / THERMAL_TAU_S)
        decay = self._decay
        # T += (AMBIENT + RISE * min(ratio, 1)^2 - T) * decay, in place
        np.minimum(ratio, 1.0, out=ratio)
        ratio *= ratio
        ratio *= STALL_RISE_K * decay
        ratio += AMBIENT_C * decay
        self.temperature *= 1.0 - decay
        self.temperature += ratio

    def states(self, idx: list[int], ticks: list[int], force: Floats, volts: float
               ) -> dict[int, ServoState]:
        """The read-back of joints ``idx`` (the bookkeeping flushed first) at present
        positions ``ticks`` (all joints) [ticks], actuator ``force`` [N m], supply [V]."""
        self.flush(force)
        load = self.load_percent(force).tolist()
        temperature = self.temperature.tolist()
        overloaded = self.overloaded().tolist()
        sids = self._ids
        # positional: id, position, load, temperature, voltage, errors
        return {sids[i]: ServoState(sids[i], ticks[i], load[i], temperature[i], volts,
                                    _OVERLOAD if overloaded[i] else _NO_ERRORS)
                for i in idx}

    def load_percent(self, force: Floats) -> Floats:
        """Load [%] of stall torque, signed in each servo's direction."""
        return 100.0 * self.map.sign * force / self.stall

    def overloaded(self) -> npt.NDArray[np.bool_]:
        return self.saturated_s > OVERLOAD_AFTER_S
