"""The emulated servo moves by the servo model (sim/emulator/servo_dynamics.py), checked on
the servo's own clock (no pty, no wall clock: ``EmulatedServo.update`` at chosen times)
against the manuals and the datasheets, and against the MuJoCo servo, a second, differently
written implementation of the same law (sim/mujoco/pendulum.py).

Oracles: the e-Manual's X register scale (KPP = P / 128 on the error in pulses, PWM 885 =
full duty) with the XL430's datasheet stall torque (1.4 N m at 11.1 V) and no-load speed
(57 rev/min), the weight's own torque m g l sin(q), and the MuJoCo replay.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robot.config.servo_file import physics_for
from robot.servo.bench_load import NONE, BenchLoad, G, parse_load
from robot.servo.models import MODELS
from robot.servo.pendulum_log import DT, PendulumLog
from robot.servo.physics import ServoPhysics
from sim.emulator.servo import EmulatedServo, ServoSpec
from sim.emulator.servo_dynamics import DynamicsSpec, ServoDynamics
from sim.mujoco.pendulum import PendulumBench

XL430 = physics_for("XL430-W250")
TPR = 4096 / (2 * math.pi)           # X series: pulses per radian
ZERO = 2048
STALL_11V = 1.4                      # XL430 datasheet [N m at 11.1 V]
NO_LOAD_11V = 57 * 2 * math.pi / 60  # XL430 datasheet [rad/s at 11.1 V]


def servo(load: BenchLoad = NONE, *, p_gain: int = 640, model: str = "XL430-W250",
          physics: ServoPhysics = XL430, voltage: float = 11.1) -> EmulatedServo:
    """One emulated servo on its own clock (t = 0), torque on, at ``p_gain`` (X)."""
    s = EmulatedServo(ServoSpec(1, model, ZERO, 0, 4095, 1_000_000), 0.0)
    s.dynamics = ServoDynamics(DynamicsSpec(model, physics, voltage, ZERO, load))
    if s.family == "dynamixel_x":
        s.set("position_p_gain", p_gain)
    s.set("torque_enable", 1)
    s.update(0.0)
    return s


def angle(s: EmulatedServo) -> float:
    return (s.get("present_position") - ZERO) / TPR


def test_a_weight_held_out_sags_by_the_manuals_stiffness() -> None:
    """0.5 kg at 0.1 m held out horizontally at factory P 640: the servo settles where its
    stiffness from the manual's scale, (P / 128) / 885 duty per pulse x the datasheet stall
    torque, balances m g l sin(q), within the gearbox's friction band."""
    load = BenchLoad(mass=0.5, length=0.1)
    s = servo(load)
    goal = math.pi / 2
    s.set("goal_position", ZERO + round(goal * TPR))
    for t in np.arange(0.1, 6.0, 0.1):
        s.update(float(t))
    q = angle(s)
    stiffness = 640 / 128 / 885 * TPR * STALL_11V            # [N m/rad]
    sag = goal - q
    weight = 0.5 * G * 0.1 * math.sin(q)
    friction = XL430.coulomb                                 # [N m] the band's half width
    assert stiffness * sag == pytest.approx(weight, abs=friction + stiffness / TPR)
    assert sag > 0.05                                        # a loaded joint lags its goal
    # what the host reads back: the duty and the load the weight asks for
    duty = weight / STALL_11V
    assert s.get("present_pwm") == pytest.approx(duty * 885, abs=0.05 * 885)
    assert s.get("present_load") == pytest.approx(duty * 1000, abs=0.05 * 1000)
    assert s.get("present_input_voltage") == 111
    assert s.get("moving") == 0


def test_a_long_step_runs_at_the_datasheet_no_load_speed() -> None:
    """Unloaded, a 2.5 rad step saturates the duty: the horn's top speed is the datasheet's
    no-load speed (the gearbox's friction included there), never more."""
    s = servo()
    s.set("goal_position", ZERO + round(2.5 * TPR))
    speeds, t = [], 0.0
    while t < 1.5:
        t += 0.005
        s.update(t)
        speeds.append(s.get("present_velocity") * 0.229 * 2 * math.pi / 60)   # [rad/s]
    assert max(speeds) == pytest.approx(NO_LOAD_11V, rel=0.03)
    assert abs(angle(s) - 2.5) <= 3 / TPR                   # arrived, within the band


def test_speed_and_torque_follow_the_supply_voltage() -> None:
    """At 7.4 V instead of 11.1 the top speed is two thirds (the motor's V / kt)."""
    top = {}
    for volts in (11.1, 7.4):
        s = servo(voltage=volts)
        s.set("goal_position", ZERO + round(2.5 * TPR))
        fastest = 0
        for k in range(1, 200):
            s.update(k * 0.005)
            fastest = max(fastest, s.get("present_velocity"))
        top[volts] = fastest
    assert top[7.4] / top[11.1] == pytest.approx(7.4 / 11.1, abs=0.03)


def test_torque_off_mid_swing_drops_the_weight_to_the_bottom() -> None:
    """Lift and drop: torque off with the arm out, only the gearbox holds back (no drive,
    no back-EMF braking with the H-bridge open): the weight falls to the bottom, not at
    once (armature and gearbox friction), and the servo reads no PWM."""
    s = servo(BenchLoad(mass=0.3, length=0.1), p_gain=1500)
    s.set("goal_position", ZERO + round(1.2 * TPR))
    for k in range(1, 400):
        s.update(k * 0.005)
    lifted = angle(s)
    s.set("torque_enable", 0)
    qs = []
    for k in range(400, 1400):
        s.update(k * 0.005)
        qs.append(angle(s))
    assert lifted > 1.0
    assert qs[10] > 0.5 * lifted                             # 50 ms in: still on its way
    assert abs(qs[-1]) < 0.1 and s.get("present_pwm") == 0


def test_an_idle_servo_at_rest_stays_put_over_a_long_gap() -> None:
    s = servo(BenchLoad(mass=0.2, length=0.1))
    s.set("goal_position", ZERO + 300)
    s.update(3.0)
    before = s.get("present_position")
    s.update(3.0 + 3600.0)                                   # an hour with no packet
    assert s.get("present_position") == before


def _emulated_log(model: str, load: BenchLoad, kp: int, t: np.ndarray,
                  goal: np.ndarray, enable: np.ndarray) -> PendulumLog:
    """What the emulated ``model`` did at 7.4 V, sampled every DT, as a pendulum log."""
    physics = physics_for(model)
    s = servo(load, p_gain=kp, model=model, physics=physics, voltage=7.4)
    s.set("torque_enable", 0)
    q, v = [], []
    for k, tk in enumerate(t):
        s.update(float(tk))
        q.append(angle(s))
        v.append(s.get("present_velocity") * 0.229 * 2 * math.pi / 60)
        s.set("torque_enable", int(enable[k]))
        s.set("goal_position", ZERO + round(goal[k] * TPR))
    zeros = np.zeros_like(t)
    return PendulumLog(source=f"emulated_{kp}", mass=load.mass, length=load.length, kp=kp,
                       vin=7.4, motor=model, trajectory="chirp", t=t, goal=goal,
                       position=np.array(q), speed=np.array(v), torque_enable=enable,
                       load=zeros, input_volts=zeros + 7.4, temp=zeros + 25)


#: Mean |emulator - MuJoCo| [rad] each trajectory must stay under. Measured (XL330-M288,
#: 0.4 kg at 0.1 m, P 600): 0.002 on the slow sine, 0.037 on the chirp, whose fast part
#: (2-3.5 Hz, the duty saturated, stick-slip at every reversal) is where the two friction
#: implementations (exact stick-slip here, MuJoCo's frictionloss constraint there) differ;
#: the step size does not change it (0.5 ms gives the same).
AGREEMENT = {"sine": 0.005, "chirp": 0.05}


@pytest.mark.parametrize("model", ["XL330-M288", "XL430-W250"])
@pytest.mark.parametrize("trajectory", ["sine", "chirp"])
def test_the_emulator_and_the_mujoco_servo_swing_the_same_pendulum(model: str,
                                                                   trajectory: str) -> None:
    """A sine (0.3 Hz) or chirp (0.3 Hz rising by 0.8 Hz/s) then a drop with torque off,
    0.4 kg at 0.1 m: the emulated servo and the MuJoCo servo (the same law, written twice:
    plain floats here, MuJoCo's actuator, damping and frictionloss there) agree."""
    physics = physics_for(model)
    load = parse_load("0.4@0.1", where="test")
    t = np.arange(0.0, 5.0, DT)
    rate = 0.4 if trajectory == "chirp" else 0.0
    goal = 1.0 * np.sin(2 * math.pi * (0.3 + rate * t) * t)
    enable = t < 4.0
    log = _emulated_log(model, load, 600, t, goal, enable)
    bench = PendulumBench([log], MODELS[model])   # the log's gains from its kp, at 7.4 V
    simulated = bench.replay(physics)
    error = float(bench.errors(simulated)[0, 0])
    assert float(np.ptp(log.position)) > 1.0                 # it really swung
    assert error < AGREEMENT[trajectory], error


def test_emulate_load_option_reads_id_mass_length() -> None:
    from robot.commands.emulate import loads_from
    from robot.errors import ConfigError

    assert loads_from(["3=0.5@0.1", "4=0@0"]) == {3: BenchLoad(0.5, 0.1), 4: BenchLoad(0.0, 0.0)}
    for bad in ("x=0.5@0.1", "3=0.5", "3=-1@0.1", "3=0.5@2"):
        with pytest.raises(ConfigError, match=r"^--load"):
            loads_from([bad])
