"""The MuJoCo mock bus: the real buses' interface, speaking ticks, with simulated servos.

Servo model, per physics step (``timestep``, default 0.002 s):

- the setpoint moves toward the goal at most ``max_speed_rad_s`` (JointConfig) per second,
  like a servo's velocity profile; the position actuator (sim.mjcf) tracks the setpoint
  with its force limited to the stall torque;
- torque off zeroes the actuator's gains (the joint goes limp); torque on restarts the
  setpoint from the present position, so the servo never snaps;
- load = actuator force / stall torque [%], signed in the servo's direction;
- temperature: a first-order thermal *model*, not a measurement: it relaxes toward
  ``AMBIENT_C + STALL_RISE_K * (force / stall torque)^2`` with time constant ``THERMAL_TAU_S``;
- errors: ``{"overload"}`` while the actuator has been saturated for more than 1 s.

Like real servos after power-up, torque starts off; the robot starts in the ``home``
keyframe (or ``pose``) with its goals at the present positions.

Time is simulation time: ``bus.clock.sleep_until(t)`` steps the physics to exactly ``t``.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Iterable, Mapping
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from robot.bus.base import Bus, ServoInfo, ServoState
from robot.config import RobotConfig
from robot.errors import BusError
from robot.servo_map import ServoMap
from sim.mjcf import FOOT_GEOMS, build_mjcf, standing_qpos

log = logging.getLogger(__name__)

AMBIENT_C = 25.0  # [°C]
STALL_RISE_K = 60.0  # steady-state rise at continuous stall torque [K]
THERMAL_TAU_S = 180.0  # thermal time constant [s]
OVERLOAD_AFTER_S = 1.0  # saturated this long → "overload" [s]
VIEW_SYNC_S = 1 / 60  # viewer refresh period [wall s]
REANCHOR_LAG_S = 0.25  # realtime: behind the wall clock by more than this → re-anchor [s]
_TIME_EPS = 1e-9  # [s]


def _check_display() -> None:
    """BusError unless a window can open (MuJoCo's viewer exits the process otherwise)."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise BusError("--view needs a display; run without --view or use `biped render`")
    import glfw

    reporting, glfw.ERROR_REPORTING = glfw.ERROR_REPORTING, "ignore"
    try:
        ok = glfw.init()
    finally:
        glfw.ERROR_REPORTING = reporting
    if not ok:
        display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        raise BusError(f"--view: cannot open display {display!r}; run without --view or "
                       f"use `biped render`")


def _launch_viewer(model: mujoco.MjModel, data: mujoco.MjData) -> Any:
    import mujoco.viewer as mujoco_viewer

    return mujoco_viewer.launch_passive(model, data)


class SimClock:
    """``robot.clock.Clock`` on simulation time: ``sleep_until`` steps the physics."""

    def __init__(self, bus: MujocoBus) -> None:
        self._bus = bus

    def now(self) -> float:
        """Simulation time [s]."""
        return float(self._bus.data.time)

    def sleep_until(self, deadline: float) -> None:
        """Step the physics until ``now() == deadline`` (no-op if already past)."""
        self._bus.advance(deadline)


class MujocoBus(Bus):
    """Simulated servo chain for ``robot`` (see the module docstring for the servo model).

    realtime: also wait on the wall clock so the sim runs at 1x; view: open the passive
    viewer (needs a display); timestep: physics step [s] (default 0.002); pose: start pose
    {joint: rad} instead of the ``home`` keyframe (standing, soles on the floor).
    """

    kind = "sim"

    def __init__(self, robot: RobotConfig, *, realtime: bool = False, view: bool = False,
                 timestep: float | None = None, pose: Mapping[str, float] | None = None) -> None:
        self.robot = robot
        self.realtime = realtime
        self.view = view
        self.timestep = timestep
        self.pose = dict(pose) if pose is not None else None
        self.servo_map = ServoMap(robot)
        self.clock = SimClock(self)
        self._id_index = {sid: i for i, sid in enumerate(robot.ids)}
        self._model: mujoco.MjModel | None = None
        self._data: mujoco.MjData | None = None
        self._viewer: Any = None
        self._renderer: mujoco.Renderer | None = None
        self._wall0 = 0.0
        self._last_sync = -math.inf

    # ------------------------------------------------------------------ lifecycle

    def open(self) -> None:
        if self._model is not None:
            return
        if self.view:
            _check_display()
        model = build_mjcf(self.robot, timestep=self.timestep).model()
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
        if self.pose is not None:
            unknown = sorted(set(self.pose) - set(self.robot.joint_names))
            if unknown:
                raise BusError(f"sim bus: pose: unknown joint {unknown[0]!r}; valid: "
                               f"{', '.join(self.robot.joint_names)}")
            data.qpos[:] = standing_qpos(model, self.pose)
        mujoco.mj_forward(model, data)
        names = self.robot.joint_names
        self._qadr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names])
        self._act = np.array([model.actuator(n).id for n in names])
        self._kp = model.actuator_gainprm[self._act, 0].copy()
        self._kv = -model.actuator_biasprm[self._act, 2].copy()
        self._stall = np.array([self.robot.servo(j).stall_torque for j in self.robot.joints])
        self._floor = model.geom("floor").id
        self._feet = tuple(model.geom(n).id for n in FOOT_GEOMS)
        self._torso = model.body("torso").id
        n = len(names)
        self._goal = data.qpos[self._qadr].copy()  # [rad]
        self._setpoint = self._goal.copy()  # [rad]
        self._enabled = np.zeros(n, dtype=bool)
        self._saturated_s = np.zeros(n)
        self._temperature = np.full(n, AMBIENT_C)
        self._model, self._data = model, data
        self._apply_torque()
        data.ctrl[self._act] = self._setpoint
        self._wall0 = time.monotonic() - data.time
        if self.view:
            self._viewer = _launch_viewer(model, data)
        log.info("sim bus open: %s, %d servos, timestep %.4f s", self.robot.name, n,
                 model.opt.timestep)

    def close(self, *, torque_off: bool = True) -> None:
        if self._model is None:
            return
        if torque_off:
            self._enabled[:] = False
            self._apply_torque()
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._model = None
        self._data = None

    @property
    def is_open(self) -> bool:
        return self._model is not None

    @property
    def standing_height(self) -> float:
        """Torso (pelvis origin) height in the ``home`` keyframe [m]."""
        return float(self.model.key("home").qpos[2])

    @property
    def model(self) -> mujoco.MjModel:
        if self._model is None:
            raise BusError("sim bus: not open; call open() (or use `with bus:`) first")
        return self._model

    @property
    def data(self) -> mujoco.MjData:
        if self._data is None:
            raise BusError("sim bus: not open; call open() (or use `with bus:`) first")
        return self._data

    # ------------------------------------------------------------------ Bus interface

    def _indices(self, ids: Iterable[int]) -> list[int]:
        """Joint indices of ``ids``; BusError naming the first unknown id (or if closed)."""
        self.model  # noqa: B018  (raises BusError if closed)
        index = self._id_index
        try:
            return [index[i] for i in ids]
        except KeyError as e:
            raise BusError(f"sim bus: servo id {e.args[0]} does not exist on robot "
                           f"{self.robot.name} ({self.robot.source}); configured ids: "
                           f"{', '.join(map(str, self.robot.ids))}") from None

    def ping(self, servo_id: int) -> int | None:
        self.model  # noqa: B018  (raises BusError if closed)
        joint = self.robot.joint_by_id(servo_id)
        return None if joint is None else self.robot.servo(joint).number

    def scan(self, ids: Iterable[int]) -> list[ServoInfo]:
        return [ServoInfo(id=i, model=servo.number, model_name=servo.name, firmware=None,
                          return_delay_us=0.0, baud=self.robot.bus.baud)
                for i in sorted(set(ids)) if self.ping(i) is not None
                for servo in [self.robot.servo(self.robot.joint_by_id(i))]]  # type: ignore[arg-type]

    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        idx = self._indices(ids)
        if enabled:
            # Torque on: the setpoint restarts from where the joint is.
            off = [i for i in idx if not self._enabled[i]]
            self._setpoint[off] = self.data.qpos[self._qadr[off]]
        self._enabled[idx] = enabled
        self._apply_torque()

    def write_goals(self, goals: Mapping[int, int]) -> None:
        if not goals:
            return
        idx = np.array(self._indices(goals))
        q = (np.array(list(goals.values()), float) - self.servo_map.zero[idx]) \
            * self.servo_map.sign[idx] / self.servo_map.ticks_per_rad[idx]
        self._goal[idx] = np.clip(q, self.servo_map.q_min[idx], self.servo_map.q_max[idx])

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        idx = self._indices(ids)
        ticks = self.present_ticks()
        force = self.data.actuator_force[self._act]
        load = 100.0 * self.servo_map.sign * force / self._stall
        volts = self.robot.bus.servo.nominal_voltage
        out: dict[int, ServoState] = {}
        for i in idx:
            errors = frozenset({"overload"}) if self._saturated_s[i] > OVERLOAD_AFTER_S \
                else frozenset()
            sid = self.servo_map.ids[i]
            out[sid] = ServoState(id=sid, position=int(ticks[i]), load=float(load[i]),
                                  temperature=float(self._temperature[i]), voltage=volts,
                                  errors=errors)
        return out

    # ------------------------------------------------------------------ simulation

    def present_ticks(self) -> npt.NDArray[np.int64]:
        """Present positions [ticks] in joint order (rounded, not clamped)."""
        q = self.data.qpos[self._qadr]
        sm = self.servo_map
        return np.rint(sm.zero + sm.sign * q * sm.ticks_per_rad).astype(np.int64)

    def _apply_torque(self) -> None:
        m = self.model
        on = self._enabled.astype(float)
        m.actuator_gainprm[self._act, 0] = self._kp * on
        m.actuator_biasprm[self._act, 1] = -self._kp * on
        m.actuator_biasprm[self._act, 2] = -self._kv * on

    def _step(self, nstep: int = 1) -> None:
        """Advance ``nstep`` physics steps; the setpoint slews only if nstep == 1 (callers
        batch steps only once every enabled setpoint has reached its goal)."""
        m, d = self.model, self.data
        dt = m.opt.timestep
        if nstep == 1:
            vmax = self.servo_map.max_speed * dt
            error = self._goal - self._setpoint
            self._setpoint = np.where(np.abs(error) <= vmax, self._goal,
                                      self._setpoint + np.sign(error) * vmax)
            d.ctrl[self._act] = self._setpoint
        mujoco.mj_step(m, d, nstep)
        span = nstep * dt
        ratio = np.abs(d.actuator_force[self._act]) / self._stall
        saturated = self._enabled & (ratio >= 0.999)
        self._saturated_s = np.where(saturated, self._saturated_s + span, 0.0)
        steady = AMBIENT_C + STALL_RISE_K * np.minimum(ratio, 1.0) ** 2
        self._temperature += (steady - self._temperature) * -math.expm1(-span / THERMAL_TAU_S)

    def _settled(self) -> bool:
        """Every torque-on setpoint is at its goal (the controls are constant)."""
        return bool(np.all((self._setpoint == self._goal) | ~self._enabled))

    def advance(self, deadline: float) -> None:
        """Step the physics until data.time == deadline [s] exactly (a last partial step
        if needed); with realtime, then wait for the wall clock. No-op if already past."""
        m, d = self.model, self.data
        dt = m.opt.timestep
        if deadline <= d.time:
            return
        while (remaining := deadline - d.time) > _TIME_EPS:
            if remaining < dt:
                m.opt.timestep = remaining
                try:
                    self._step()
                finally:
                    m.opt.timestep = dt
            elif self._settled():
                self._step(max(1, int(remaining / dt + 1e-6)))
            else:
                self._step()
        d.time = deadline
        if self.realtime:
            self._wait_wall(deadline)
        if self._viewer is not None:
            self._sync_viewer()

    def _wait_wall(self, deadline: float) -> None:
        wall_deadline = self._wall0 + deadline
        lag = time.monotonic() - wall_deadline
        if lag > REANCHOR_LAG_S:
            log.debug("sim bus: %.3f s behind real time; re-anchoring", lag)
            self._wall0 += lag
            return
        while (remaining := wall_deadline - time.monotonic()) > 0:
            time.sleep(remaining)

    def _sync_viewer(self) -> None:
        now = time.monotonic()
        if now - self._last_sync < VIEW_SYNC_S:
            return
        self._last_sync = now
        if self._viewer.is_running():
            self._viewer.sync()

    # ------------------------------------------------------------------ observation

    def base_pose(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Torso (pelvis frame) position [m] and orientation quaternion (w, x, y, z)."""
        q = self.data.qpos
        return q[0:3].copy(), q[3:7].copy()

    def upright_angle(self) -> float:
        """Angle between the torso's z axis and world z [rad] (0 upright, pi/2 lying)."""
        _, x, y, _ = self.data.qpos[3:7]
        qn = float(np.dot(self.data.qpos[3:7], self.data.qpos[3:7]))
        return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y) / qn)))

    def contacts_feet(self) -> tuple[bool, bool]:
        """(right, left): is each foot box touching the floor (as of the last step)."""
        d = self.data
        pairs = d.contact.geom[: d.ncon]
        touching = []
        for foot in self._feet:
            hit = ((pairs[:, 0] == foot) & (pairs[:, 1] == self._floor)) \
                | ((pairs[:, 1] == foot) & (pairs[:, 0] == self._floor))
            touching.append(bool(hit.any()))
        return touching[0], touching[1]

    def render(self, width: int, height: int, camera: str = "track") -> npt.NDArray[np.uint8]:
        """An offscreen RGB frame (height, width, 3) of the current state (needs MUJOCO_GL
        set, e.g. egl, before mujoco is imported). Reuses one renderer per size."""
        m = self.model
        r = self._renderer
        if r is None or (r.width, r.height) != (width, height):
            if r is not None:
                r.close()
            try:
                r = mujoco.Renderer(m, height=height, width=width)
            except ValueError as e:
                raise BusError(f"sim bus: render {width}x{height}: {e}") from e
            self._renderer = r
        try:
            r.update_scene(self.data, camera=camera)
        except ValueError as e:
            raise BusError(f"sim bus: render: no camera {camera!r} ({e})") from e
        return r.render()
