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

What the host reads back besides position and speed: the motor state (:attr:`ServoDynamics.duty`,
:attr:`ServoDynamics.torque_share` of the stall torque at the supply, :attr:`current_a`)
for ``servo_effort.write_effort``, which turns it into each table's load / current / PWM
registers, and the supply in Present (Input) Voltage (0.1 V).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from robot.servo import law as servo_law
from robot.servo.bench_load import NONE, BenchLoad
from robot.servo.firmware import law_terms
from robot.servo.gains import GAIN_SETS
from robot.servo.models import MODELS
from robot.servo.physics import ServoPhysics

STEP_S = 0.002                 # integration step [s]: the MuJoCo robot's physics step
P1_SPEED_UNIT_RPM = 0.111      # AX-12A / MX-28 Moving Speed(32) unit [rev/min]
STS_SPEED_MASK = 0x7FFF        # STS Goal Speed(46): bit 15 is the direction
P1_SPEED_MASK = 0x3FF
#: The supply read-back (0.1 V): X series / Protocol 1.0 and Feetech names.
VOLTAGE_REGISTERS = ("present_input_voltage", "present_voltage")


class ServoRegisters(Protocol):
    """What the model reads of an emulated servo: its registers by name, its table's bytes
    and rows (``mem``, ``regs``: (name, entry with .address, .size))."""

    family: str
    mem: bytearray

    @property
    def regs(self) -> Sequence[tuple[str, Any]]: ...

    def get(self, name: str) -> int: ...


@dataclass(frozen=True)
class DynamicsSpec:
    """One emulated servo's model: ``model``: a key of ``robot.servo.models.MODELS``;
    physics; voltage: its supply [V]; load: what it carries; zero_ticks: the position of
    q = 0 (the arm hanging down) [ticks, actual]."""

    model: str
    physics: ServoPhysics
    voltage: float
    zero_ticks: int
    load: BenchLoad = NONE


class ServoDynamics:
    """The model's state for one servo: speed ``dq`` [rad/s], the firmware's internal goal
    [rad], the integral of the error [rad s], the last duty and motor torque [N m];
    ``resting``: held at rest by friction with nothing left to change (the servo's
    registers may hold until the next write)."""

    def __init__(self, spec: DynamicsSpec) -> None:
        self.spec = spec
        model = MODELS[spec.model]
        self.ticks_per_rad = model.ticks_per_rad
        self._gain_names = GAIN_SETS[model.gain_set].names if model.gain_set else ()
        self.dq = self.internal = self.integral = self.duty = self.motor = 0.0
        self.on = self.resting = False
        self._pos: float | None = None
        self._law_key = b""
        self._law: servo_law.Law | None = None
        self._span = (0, 0)
        self._speed_register: str | None = None    # the host's speed register, "" if none

    @property
    def torque_share(self) -> float:
        """The motor's torque as a share of the stall torque at the supply [-1..1]."""
        stall = self.spec.physics.stall_torque(self.spec.voltage)
        return max(-1.0, min(1.0, self.motor / stall)) if stall else 0.0

    @property
    def current_a(self) -> float:
        """The motor's current [A]: its torque / kt."""
        return abs(self.motor) / self.spec.physics.kt

    @property
    def voltage_tenths(self) -> int:
        return round(self.spec.voltage * 10)

    def law(self, servo: ServoRegisters) -> servo_law.Law:
        """The law at the gains in ``servo``'s registers (recomputed when the bytes that
        hold them change)."""
        if self._law is None:
            rows = [e for n, e in servo.regs if n in self._gain_names]
            self._span = (min((e.address for e in rows), default=0),
                          max((e.address + e.size for e in rows), default=0))
        key = bytes(servo.mem[self._span[0]:self._span[1]])
        if self._law is None or key != self._law_key:
            model = MODELS[self.spec.model]
            names = {n for n, _ in servo.regs}
            gains = {**model.factory_gains,
                     **{n: servo.get(n) for n in self._gain_names if n in names}}
            terms = law_terms(model, self.spec.physics, gains)
            self._law = servo_law.Law.of(terms, self.spec.physics, self.spec.voltage)
            self._law_key = key
        return self._law

    def _slew_limit(self, servo: ServoRegisters, law: servo_law.Law) -> float:
        """The goal slew [rad/s]: the firmware's, and the host's speed register."""
        if self._speed_register is None:
            names = {n for n, _ in servo.regs}
            self._speed_register = ("goal_speed" if servo.family.startswith("feetech")
                                    and "goal_speed" in names else
                                    "moving_speed" if "moving_speed" in names else "")
        if self._speed_register == "goal_speed":
            steps = servo.get("goal_speed") & STS_SPEED_MASK
            host = steps / self.ticks_per_rad if steps else math.inf
        elif self._speed_register == "moving_speed":
            units = servo.get("moving_speed") & P1_SPEED_MASK
            host = units * P1_SPEED_UNIT_RPM * 2 * math.pi / 60 if units else math.inf
        else:
            host = math.inf        # X: Profile Velocity is a gain register (law_terms)
        return min(law.max_velocity, host)

    def advance(self, servo: ServoRegisters, pos: float, goal: float, dt: float, *,
                torque: bool, stuck: bool) -> tuple[float, float]:
        """Integrate ``dt`` [s] from ``pos`` toward ``goal`` [ticks, actual]; (new position
        [ticks], speed [ticks/s]). ``stuck``: an injected jam, the horn does not move."""
        tpr, zero = self.ticks_per_rad, self.spec.zero_ticks
        if self._pos is None or pos != self._pos:
            self.dq = 0.0          # placed by hand (power on, factory reset, a mode change)
        q, goal_q = (pos - zero) / tpr, (goal - zero) / tpr
        law = self.law(servo)
        if torque and not self.on:     # torque on: the firmware starts from where it is
            self.internal, self.integral = q, 0.0
        self.on = torque
        if stuck:
            self.dq, self.resting = 0.0, True
            self.duty = servo_law.duty(law, goal_q, q, 0.0, 0.0) if torque else 0.0
            self.motor = servo_law.motor_torque(law, self.duty, 0.0, on=torque)
        else:
            q = self._integrate(law, q, goal_q, dt, self._slew_limit(servo, law))
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
        self.resting = False
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
                        self.resting = True
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
