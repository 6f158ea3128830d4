"""The physics steps of one control tick on the sim bus (sim.mujoco.bus.MujocoBus.advance).

Whole ``timestep`` steps up to a stop time, then one shorter step to land on it exactly.
Before each step the servos' setpoints slew toward their goals (sim.mujoco.servos) and the
actuators' ctrl follows; once every setpoint has settled the remaining whole steps run in
one ``mj_step`` call (the same simulation: a settled slew changes nothing).

Sensors: MuJoCo computes the sensors (the IMU's gyro, accelerometer and orientation: the
accelerometer needs its own pass over the bodies, ``mj_rnePostConstraint``) in the forward
pass at the start of every step, and nothing reads them but the control tick between two
``advance`` calls. So the steps of a tick skip them (``mjDSBL_SENSOR``) except the last,
whose values are the ones read, as before: the same ``sensordata`` after every ``advance``
and the same physics (sensors feed nothing back), one sensor pass per tick instead of one
per step. Which step is the last is known exactly: MuJoCo advances ``data.time`` by
``opt.timestep`` per step, and the same float additions here say when the span ends.
"""

from __future__ import annotations

import mujoco

from sim.mujoco.servo_law import ChainLaw
from sim.mujoco.servos import SimServos

_TIME_EPS = 1e-9  # [s]: what counts as having arrived (as the bus)
NO_SENSORS = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)


def physics_to(model: mujoco.MjModel, data: mujoco.MjData, servos: SimServos, law: ChainLaw,
               stop: float, *, sensed: bool) -> None:
    """Step ``data`` up to sim time ``stop`` [s] (module docstring). ``sensed``: the last
    step computes the sensors (the end of a tick); the other steps never do."""
    opt, d, dt = model.opt, data, model.opt.timestep
    ctrl, act = data.ctrl, law.act
    flags = opt.disableflags
    off = flags | NO_SENSORS
    opt.disableflags = off
    try:
        while (remaining := stop - d.time) > _TIME_EPS:
            if not servos.settled:
                ctrl[act] = law.ctrl(servos.slew(dt if dt < remaining else remaining))
            if remaining < dt:            # the short step lands on stop: the last one
                opt.timestep = remaining
                if sensed:
                    opt.disableflags = flags
                try:
                    mujoco.mj_step(model, d)
                finally:
                    opt.timestep = dt
                continue
            n = int(remaining / dt + 1e-6) if servos.settled else 1
            end = d.time
            for _ in range(n):            # MuJoCo's time after the n steps
                end += dt
            if sensed and stop - end <= _TIME_EPS:   # the span's last step is among them
                if n > 1:
                    mujoco.mj_step(model, d, n - 1)
                opt.disableflags = flags
                mujoco.mj_step(model, d)
            else:
                mujoco.mj_step(model, d, n)
    finally:
        opt.disableflags = flags
