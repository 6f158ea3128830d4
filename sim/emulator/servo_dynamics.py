"""The emulated servo moves by the servo model: the law the driver's gains set
(``robot.servo.law``, the same pure function the MuJoCo servo is held to), a DC motor at the
supply voltage, gearbox friction and armature, turning the horn and whatever it carries
(``robot.servo.bench_load``: a weight on an arm, or nothing).

Time: the state advances with the wall clock, lazily, at each packet that reaches the
servo (``servo_motion.advance`` calls :meth:`ServoDynamics.advance` with the elapsed time),
in steps of at most ``STEP_S``; a servo at rest whose friction holds it, with nothing left
to change (no goal slew, no I term), skips the rest of the interval, so an idle chain costs
nothing however long the gap. The integrator: semi-implicit Euler, every torque
proportional to the speed (back-EMF, viscous, the D term) taken implicitly; the friction
holds the shaft at rest while the other torques stay within it, and a speed that would
cross zero within a step stops there.

Gains are read from the servo's own registers (what the driver wrote): the gain set of its
model (``robot.servo.gains``), through the family's register scale
(``robot.servo.firmware``). The host's speed registers slew the firmware's goal as the
manuals say: X Profile Velocity (a gain register), STS Goal Speed(46) (steps/s, 0 = no
limit), AX/MX Moving Speed(32) (0.111 rev/min, 0 = no limit).

What the host reads back besides position and speed (:meth:`ServoDynamics.report`), each
from the model: X Present PWM(124) (885 = full duty) and Present Load(126) (0.1 % of the
stall torque at the supply, the XL430's unit), AX/MX Present Load(40) (0.1 %, bit 10 =
CW), STS Present Load(60) (the duty in 0.1 %, bit 10 = negative) and Present Current(69)
(6.5 mA), and the supply in Present (Input) Voltage (0.1 V).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from robot.servo import law as servo_law
from robot.servo.bench_load import NONE, BenchLoad
from robot.servo.firmware import law_terms
from robot.servo.gains import GAIN_SETS
from robot.servo.models import MODELS
from robot.servo.physics import ServoPhysics

STEP_S = 0.002                 # integration step [s]: the MuJoCo robot's physics step
X_PWM_FULL = 885               # X e-Manual: Present PWM(124) at 100 % duty
P1_SPEED_UNIT_RPM = 0.111      # AX-12A / MX-28 Moving Speed(32) unit [rev/min]
STS_CURRENT_UNIT_A = 0.0065    # STS memory table: Present Current(69) unit [A]
LOAD_FULL = 1000               # Present Load in 0.1 % units at 100 %
P1_LOAD_SIGN = 0x400           # AX/MX Present Load(40) bit 10: CW load
STS_LOAD_SIGN = 0x400          # STS Present Load(60) bit 10: negative


class ServoState(Protocol):
    """What the model reads and writes of an emulated servo: its registers by name, its
    table's bytes and rows (``mem``, ``regs``: (name, entry with .address, .size))."""

    family: str
    stuck: bool
    mem: bytearray

    @property
    def regs(self) -> Sequence[tuple[str, Any]]: ...

    def get(self, name: str) -> int: ...

    def set(self, name: str, value: int) -> None: ...


@dataclass(frozen=True)
class DynamicsSpec:
    """One emulated servo's model: ``model``: a key of ``robot.servo.models.MODELS``;
    physics; voltage: its supply [V]; load: what it carries; zero_ticks: the position of
    q = 0 (the arm hanging down) [ticks]."""

    model: str
    physics: ServoPhysics
    voltage: float
    zero_ticks: int
    load: BenchLoad = NONE


@dataclass
class ServoDynamics:
    """The model's state for one servo: speed [rad/s], the firmware's internal goal [rad],
    the integral of the error [rad s], the last duty and motor torque [N m]; ``pinned``:
    read-back registers the emulator's back door set by hand (left as set)."""

    spec: DynamicsSpec
    dq: float = 0.0
    internal: float = 0.0
    integral: float = 0.0
    on: bool = False
    duty: float = 0.0
    motor: float = 0.0
    pinned: set[str] = field(default_factory=set)
    _pos: float | None = None
    _law_key: bytes = b""
    _law: servo_law.Law | None = None
    _span: tuple[int, int] = (0, 0)
    _reported: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        model = MODELS[self.spec.model]
        self.ticks_per_rad = model.ticks_per_rad
        self._gain_names = GAIN_SETS[model.gain_set].names if model.gain_set else ()

    def law(self, servo: ServoState) -> servo_law.Law:
        """The law at the gains in ``servo``'s registers (recomputed when the bytes that
        hold them change)."""
        if self._law is None:
            rows = [e for n, e in servo.regs if n in self._gain_names]
            self._span = (min((e.address for e in rows), default=0),
                          max((e.address + e.size for e in rows), default=0))
        key = bytes(servo.mem[self._span[0]:self._span[1]])
        if self._law is None or key != self._law_key:
            model = MODELS[self.spec.model]
            names = set(dict(servo.regs))
            gains = {**model.factory_gains,
                     **{n: servo.get(n) for n in self._gain_names if n in names}}
            terms = law_terms(model, self.spec.physics, gains)
            self._law = servo_law.Law.of(terms, self.spec.physics, self.spec.voltage)
            self._law_key = key
        return self._law

    def _slew_limit(self, servo: ServoState, law: servo_law.Law) -> float:
        """The goal slew [rad/s]: the firmware's, and the host's speed register."""
        family = servo.family
        if family == "feetech_sts":
            steps = servo.get("goal_speed") & 0x7FFF
            host = steps / self.ticks_per_rad if steps else math.inf
        elif family == "dynamixel_p1":
            units = servo.get("moving_speed") & 0x3FF
            host = units * P1_SPEED_UNIT_RPM * 2 * math.pi / 60 if units else math.inf
        else:
            host = math.inf        # X: Profile Velocity is a gain register (law_terms)
        return min(law.max_velocity, host)

    def advance(self, servo: ServoState, pos: float, dt: float) -> tuple[float, float]:
        """Integrate ``dt`` [s] from ``pos`` [ticks]; (new position [ticks], speed
        [ticks/s])."""
        tpr, zero = self.ticks_per_rad, self.spec.zero_ticks
        if self._pos is None or pos != self._pos:
            self.dq = 0.0          # placed by hand (power on, factory reset, a test)
            self._reported.clear()  # ... and the read-backs with it
        q = (pos - zero) / tpr
        goal = (servo.get("goal_position") - zero) / tpr
        on = bool(servo.get("torque_enable"))
        if servo.stuck:            # an injected jam: the horn does not move
            self.dq, self.on = 0.0, on
            self._pos = pos
            return pos, 0.0
        law = self.law(servo)
        if on and not self.on:     # torque on: the firmware starts from where it is
            self.internal, self.integral = q, 0.0
        self.on = on
        q = self._integrate(law, q, goal, dt, self._slew_limit(servo, law))
        self._pos = zero + q * tpr
        return self._pos, self.dq * tpr

    def _integrate(self, law: servo_law.Law, q: float, goal: float, dt: float,
                   slew: float) -> float:
        on, load = self.on, self.spec.load
        inertia = law.armature + load.inertia
        moment = load.moment
        steps = math.ceil(dt / STEP_S - 1e-9)
        h = dt / steps if steps else 0.0
        dq, internal, integral = self.dq, self.internal, self.integral
        motor, duty = self.motor, self.duty
        for _ in range(steps):
            if on:
                internal = servo_law.slew(internal, goal, slew, h)
                duty = servo_law.duty(law, internal, q, dq, integral)
                # the duty's own speed term, taken implicitly while it is not saturated
                kd = law.drive * law.kd if abs(duty) < law.max_duty else 0.0
                drive = law.drive * duty + kd * dq
                damping = law.back_emf + law.viscous + kd
                motor = drive - law.back_emf * dq
            else:
                drive, damping, motor, duty = 0.0, law.viscous, 0.0, 0.0
            net = drive - moment * math.sin(q)
            hold = servo_law.friction(law, dq, motor)
            if dq == 0.0:
                if abs(net) <= hold:
                    if not on or (law.ki == 0.0 and internal == goal):
                        break              # held at rest, nothing left to change
                    new = 0.0
                else:
                    new = h * (net - math.copysign(hold, net)) / (inertia + h * damping)
            else:
                new = (inertia * dq + h * (net - math.copysign(hold, dq))) / (inertia + h * damping)
                if new * dq < 0.0:
                    new = 0.0              # the speed crossed zero within the step
            if on and law.ki:
                integral += servo_law.error(law, internal, q) * h
            dq = new
            q += h * dq
        self.dq, self.internal, self.integral = dq, internal, integral
        self.duty, self.motor = duty, motor
        return q

    def report(self, servo: ServoState, names: frozenset[str]) -> None:
        """Write the model's PWM, load, current and supply into ``servo``'s registers
        (those of ``names`` it has and no one pinned)."""
        stall = self.spec.physics.stall_torque(self.spec.voltage)
        share = max(-1.0, min(1.0, self.motor / stall)) if stall else 0.0
        load = round(abs(share) * LOAD_FULL)
        tenths = round(self.spec.voltage * 10)
        values: dict[str, int] = {}
        if servo.family == "dynamixel_x":
            values = {"present_pwm": round(self.duty * X_PWM_FULL),
                      "present_load": round(share * LOAD_FULL),
                      "present_input_voltage": tenths}
        elif servo.family == "dynamixel_p1":
            values = {"present_load": load | (P1_LOAD_SIGN if share < 0 else 0),
                      "present_voltage": tenths}
        elif servo.family == "feetech_sts":
            pwm = round(abs(self.duty) * LOAD_FULL)
            amps = abs(self.motor) / self.spec.physics.kt
            values = {"present_load": pwm | (STS_LOAD_SIGN if self.duty < 0 else 0),
                      "present_current": round(amps / STS_CURRENT_UNIT_A),
                      "present_voltage": tenths}
        for name, v in values.items():
            if name in names and name not in self.pinned and self._reported.get(name) != v:
                servo.set(name, v)
                self._reported[name] = v
