"""A servo at rest stops short of its goal, and the model's friction is what holds it
(issue 34; docs/servos.md, "At rest"). Oracle: the real XL330-M288 recordings
(../shared/servo_logs/bam/xl330 beside the repository, Rhoban/bam): each opens with the
servo at rest on goal 0, torque on, the arm hanging, several pulses off the goal while
the firmware keeps pushing (Present PWM); the bundled model's friction at rest must hold
what the recording shows held: the motor's torque (PWM of 885, times the stall torque at
the log's supply) plus gravity on the arm pushing the same way.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from robot.config.servo_file import physics_for
from robot.servo.pendulum_log import read_log

BAM = Path(__file__).resolve().parents[1].parent / "shared" / "servo_logs" / "bam"
LOGS = sorted((BAM / "xl330").glob("*.json.gz"))
PULSE = 2 * math.pi / 4096          # XL330-M288: 4096 pulses a turn
PWM_FULL = 885.0                    # e-Manual: PWM Limit 885 = 100 % duty
G = 9.81


def test_the_recorded_rest_states_are_held_by_the_model_friction() -> None:
    physics = physics_for("XL330-M288")
    shorts, held = [], []
    for path in LOGS:
        log = read_log(path)
        still = int(np.argmax(np.abs(log.goal - log.goal[0]) > PULSE))   # the goal moves
        q = log.position[:still]
        assert still > 0 and np.ptp(q) <= 1.01 * PULSE, path.name   # at rest (a pulse of jitter)
        pwm = log.load[0] - 65536 if log.load[0] > 32767 else log.load[0]
        motor = pwm / PWM_FULL * physics.stall_torque(log.vin)
        gravity = -(log.mass * log.length + log.arm_mass * log.length / 2) * G * math.sin(q[0])
        error = (log.goal[0] - q[0]) / PULSE
        pushed = motor + gravity                     # what the gears held [N m]
        hold = physics.coulomb + physics.stribeck + physics.load_friction * abs(motor)
        assert abs(pushed) <= hold, (path.name, error, pwm, pushed, hold)
        shorts.append(round(abs(error)))
        held.append(abs(pushed))
    assert len(LOGS) == 16
    assert max(shorts) >= 8 and sum(s >= 2 for s in shorts) >= 8, shorts   # not on the goal
    assert max(held) > 0.009, held                   # the gears held ~10 mN m at least once
