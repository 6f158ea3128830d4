"""The MuJoCo mock bus: the real buses' interface, speaking ticks, with simulated servos.

The servo model: goal → setpoint slewed at ``max_speed_rad_s`` (or the firmware's own goal
slew, if slower) → the firmware's position law through a DC motor at the supply voltage,
with gearbox friction and armature (``sim.mujoco.servo_law``: MuJoCo's actuator, joint
damping, frictionloss and armature carry it; once per control tick the load-dependent
friction and, where the firmware has them, the dead band and I term are updated). Goals,
torque, load, the thermal model and the overload flag live in ``sim.mujoco.servos``; its
docstring states the discretisation. Like real servos after
power-up, torque starts off; the robot starts in the ``home`` keyframe (or ``pose``) with
its goals at the present positions.

Time is simulation time: ``bus.clock.sleep_until(t)`` steps the physics to exactly ``t``
(whole ``timestep`` steps, batched into one ``mj_step`` call once the setpoints are
constant, then one shorter step to land on ``t``; the sensors computed in the last step
only: sim.mujoco.stepping).
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from robot.bus.base import Bus, ServoInfo, ServoState
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.config.world import World
from robot.errors import BusError
from sim.mujoco.mjcf import build_mjcf, foot_geoms, standing_qpos
from sim.mujoco.observation import BodyObservation
from sim.mujoco.push_state import body_state
from sim.mujoco.run_watch import SimRunWatch
from sim.mujoco.servo_law import ChainLaw, robot_servos
from sim.mujoco.servos import AMBIENT_C, SimServos
from sim.mujoco.stepping import physics_to
from sim.mujoco.view import OffscreenRenderer, SimClock, WallPacer, check_display, launch_viewer
from sim.mujoco.world import PUSH_WINDOW_S, TimedForces, heading_force
from sim.mujoco.world_scene import apply_world_to_model, place_on_floor

__all__ = ["AMBIENT_C", "MujocoBus", "SimClock"]

log = logging.getLogger(__name__)

_TIME_EPS = 1e-9  # [s]


class MujocoBus(BodyObservation, Bus):
    """Simulated servo chain for ``robot`` (see the module docstring for the servo model).

    realtime: also wait on the wall clock so the sim runs at 1x; view: open the passive
    viewer (needs a display); timestep: physics step [s] (default 0.002); pose: start pose
    {joint: rad} instead of the ``home`` keyframe (standing, soles on the floor); world:
    perturbations (``robot.config.world.World``: slope, bumps, latency, friction, mass; pushes via
    ``push`` / ``sim.mujoco.world.PushScheduler``), None for the plain scene.
    """

    kind = "sim"

    def __init__(self, robot: RobotConfig, *, realtime: bool = False, view: bool = False,
                 timestep: float | None = None, pose: Mapping[str, float] | None = None,
                 world: World | None = None) -> None:
        self.robot = robot
        self.world = world
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
        self._renderer = OffscreenRenderer()
        self._pacer = WallPacer()
        self._forces = TimedForces()  # pushes on the torso in progress

    # ------------------------------------------------------------------ lifecycle

    def open(self) -> None:
        if self._model is not None:
            return
        if self.view:
            check_display()
        world = self.world
        model = build_mjcf(self.robot, timestep=self.timestep, world=world).model()
        data = mujoco.MjData(model)
        if world is not None:
            apply_world_to_model(model, data, world)
        mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
        if self.pose is not None:
            unknown = sorted(set(self.pose) - set(self.robot.joint_names))
            if unknown:
                raise BusError(f"sim bus: pose: unknown joint {unknown[0]!r}; valid: "
                               f"{', '.join(self.robot.joint_names)}")
            data.qpos[:] = standing_qpos(model, self.pose)
        if world is not None:
            place_on_floor(data, world)
        mujoco.mj_forward(model, data)
        names = self.robot.joint_names
        self._qadr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names])
        self._act = np.array([model.actuator(n).id for n in names])
        dof = np.array([model.jnt_dofadr[model.joint(n).id] for n in names])
        law = robot_servos(self.robot)
        self._law = ChainLaw(model, data, law, self._act, dof, self._qadr)
        self._ground = np.flatnonzero((model.geom_bodyid == 0)
                                      & ((model.geom_contype | model.geom_conaffinity) != 0))
        self._feet = foot_geoms(model)
        self._torso = model.body("torso").id
        self._servos = SimServos(self.servo_map, law.force, data.qpos[self._qadr],
                                 latency_s=world.latency_s if world is not None else 0.0,
                                 max_speed=np.minimum(self.servo_map.max_speed,
                                                      law.max_velocity))
        self._forces = TimedForces()
        self._model, self._data = model, data
        self._apply_torque()
        data.ctrl[self._act] = self._servos.setpoint
        self._pacer.anchor(data.time)
        if self.view:
            self._viewer = launch_viewer(model, data)
        log.info("sim bus open: %s, %d servos, timestep %.4f s", self.robot.name, len(names),
                 model.opt.timestep)

    def close(self, *, torque_off: bool = True) -> None:
        if self._model is None:
            return
        if torque_off:
            self._servos.enabled[:] = False
            self._apply_torque()
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
        self._renderer.close()
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
    def floor_normal(self) -> tuple[float, float, float]:
        """Unit normal of the floor plane through the origin (world frame)."""
        return self.world.floor_normal() if self.world is not None else (0.0, 0.0, 1.0)

    def run_watch(self) -> SimRunWatch:
        """A watch for one run on the open bus (robot.run.spec.WatchedBus)."""
        return SimRunWatch(self.model, self.data, self.robot, world=self.world,
                           standing_height=self.standing_height,
                           floor_normal=self.floor_normal, push_target=self)

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
        self._servos.set_torque(idx, enabled, self.data.qpos[self._qadr])
        self._apply_torque()

    def write_goals(self, goals: Mapping[int, int]) -> None:
        if not goals:
            return
        d = self.data  # BusError if closed
        servos = self._servos
        idx = servos.index_all(goals)
        if idx is None:
            idx = np.array(self._indices(goals))
        servos.write(idx, servos.to_rad(goals, idx), d.time)

    def write_joint_goals(self, servo_map: ServoMap, q: npt.NDArray[np.float64]) -> None:
        if servo_map.ids != self.servo_map.ids:
            return super().write_joint_goals(servo_map, q)
        self._servos.write_ticks(servo_map.tick_vector(q), self.data.time)

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        idx = self._indices(ids)
        volts = self.robot.voltage(self.robot.joints[0])   # one supply for the bus
        return self._servos.states(idx, self.present_ticks().tolist(),
                                   self.data.actuator_force[self._act], volts)

    # ------------------------------------------------------------------ simulation

    def present_ticks(self) -> npt.NDArray[np.int64]:
        """Present positions [ticks] in joint order (rounded, not clamped)."""
        q = self.data.qpos[self._qadr]
        sm = self.servo_map
        return np.rint(sm.zero + sm.sign * q * sm.ticks_per_rad).astype(np.int64)

    def _apply_torque(self) -> None:
        self._law.set_torque(self._servos.enabled)

    def advance(self, deadline: float) -> None:
        """Step the physics until data.time == deadline [s] exactly (a last partial step
        if needed), applying delayed goals when they fall due; with realtime, then wait for
        the wall clock. No-op if already past."""
        d = self.data
        t0 = d.time
        if deadline <= t0:
            return
        servos = self._servos
        self._law.tick(servos.setpoint, deadline - t0)
        while (event := self._next_event()) < deadline - _TIME_EPS:
            if event > d.time:
                physics_to(self.model, d, servos, self._law, event, sensed=False)
                d.time = event
            self._events_due(event)
        physics_to(self.model, d, servos, self._law, deadline, sensed=True)
        d.time = deadline
        if servos.pending or self._forces.active:   # delayed goals, pushes in progress
            self._events_due(deadline)
        if servos.add_time(deadline - t0):    # the thermal and saturation bookkeeping
            servos.flush(d.actuator_force[self._act])
        if self.realtime:
            self._pacer.wait(deadline)
        if self._viewer is not None:
            self._pacer.sync_viewer(self._viewer)

    def _next_event(self) -> float:
        """Sim time [s] of the next delayed goal or push end (inf if none)."""
        return min(self._servos.next_due(), self._forces.next_end())

    def _events_due(self, now: float) -> None:
        self._servos.release_due(now)
        self._forces.end_due(now, self.data.xfrc_applied[self._torso])

    def push(self, jx: float, jy: float, *, window_s: float = PUSH_WINDOW_S) -> dict[str, Any]:
        """An impulse on the torso now: jx forward, jy left in its heading frame (yaw only)
        [N*s], a force J / window_s [N] at its centre of mass for window_s [s] of sim
        time. Returns the body's state before it (sim.mujoco.push_state)."""
        if not window_s > 0:
            raise BusError(f"sim bus: push window must be > 0 s, got {window_s}")
        d, state = self.data, body_state(self.model, self.data, self.contacts_feet())
        force = heading_force(d.qpos[3:7].tolist(), jx, jy) / window_s
        self._forces.start(d.time + window_s, force, d.xfrc_applied[self._torso])
        return state
