"""Recording a run as MCAP (``--record run.mcap``), the log format robotics viewers open
(Foxglove as-is): a tick observer of the loop, like the CSV/JSONL recorder.

Channels, each with its schema in the file (ROS 2 message definitions, CDR-encoded, from
the ``rosbags`` type store: no ROS install needed; Foxglove's own JSON schema for the log):

- ``/joint_commands`` (sensor_msgs/msg/JointState), every tick: what was sent [rad];
- ``/joint_states`` (sensor_msgs/msg/JointState), read-back ticks: the positions [rad] and
  the loads as effort [N m];
- ``/servo_temperatures`` (sensor_msgs/msg/Temperature), read-back ticks, one message a
  servo (frame_id: its joint) [deg C];
- ``/imu`` (sensor_msgs/msg/Imu), each new IMU sample (a run with balance);
- ``/torso_pose`` (geometry_msgs/msg/PoseStamped), every tick in the simulation (frame_id
  "world") [m];
- ``/gait/params`` (biped.GaitParams: a JSON schema, one number a parameter; ROS has no
  message for named values), the first tick and each change of the source's parameters;
- ``/events`` (foxglove.Log, JSON): state changes, a stop and its reason, the end, cues,
  timecode.

Times: every message's log time and header stamp is the tick's, on the loop's clock,
anchored to the wall clock (UNIX epoch) at the first tick; a simulation faster than real
time keeps its own time base. ``/joint_states`` is stamped when the reply was in (on the
loop's clock from the same anchor, the sim's on the sim bus: a take's ``present_t``; the
log time is the tick's).
Effort is the servo's load (% of its maximum torque) times its stall torque. A channel
appears at its first message; the run's take header (robot, joints, rate) is the metadata
record ``biped`` (``take_header``: its JSON), so
``biped sim-gap`` and ``biped plot`` read the file (robot/previs/mcap_read.py).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, Protocol, runtime_checkable

import numpy as np
from mcap.writer import CompressionType, Writer
from rosbags.typesys import Stores, get_typestore

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.loop.telemetry import Telemetry
from robot.motion.takes import TakeHeader

SUFFIX = ".mcap"
#: Chunks this size [bytes] (compressed on the loop's thread: small keeps a tick short).
CHUNK_BYTES = 64 * 1024
LEVELS = {"debug": 1, "info": 2, "warning": 3, "error": 4, "fatal": 5}
#: foxglove.Log as its JSON schema (Foxglove's schema: timestamp, level 0-5, message, name,
#: file, line).
LOG_SCHEMA = {
    "title": "foxglove.Log", "type": "object", "properties": {
        "timestamp": {"type": "object", "properties": {"sec": {"type": "integer"},
                                                       "nsec": {"type": "integer"}}},
        "level": {"type": "integer", "enum": [0, 1, 2, 3, 4, 5]},
        "message": {"type": "string"}, "name": {"type": "string"},
        "file": {"type": "string"}, "line": {"type": "integer"}}}
ROS_TYPES = ("sensor_msgs/msg/JointState", "sensor_msgs/msg/Temperature",
             "sensor_msgs/msg/Imu", "geometry_msgs/msg/PoseStamped")


def is_mcap(path: str | Path) -> bool:
    return Path(path).suffix == SUFFIX


@runtime_checkable
class BodyPose(Protocol):
    """A bus that knows where the torso is (the simulated bus): position [m] and
    orientation (w, x, y, z) in the world."""

    def base_pose(self) -> tuple[Any, Any]: ...


class McapRecorder:
    """``header``: the run's take header (robot, joints, rate; kept as metadata);
    ``params``: the source's live parameters (None: the run has none); ``body``: the bus,
    if it reports the torso's pose. ``log(text)`` adds an event from the loop's thread."""

    def __init__(self, path: str | Path, robot: RobotConfig, header: TakeHeader, *,
                 params: Callable[[], GaitParams | None] | None = None,
                 body: object | None = None) -> None:
        self.path = Path(path)
        if not is_mcap(self.path):
            raise ConfigError(f"--record {path}: an MCAP file name ends in {SUFFIX}")
        self.robot, self.header = robot, header
        self.names = list(robot.joint_names)
        self.ids = robot.ids
        self._stall = [robot.servo(j).stall_torque for j in robot.joints]
        self._params = params
        self._body = body if isinstance(body, BodyPose) else None
        self._store = get_typestore(Stores.ROS2_HUMBLE)
        self._file: IO[bytes] | None = None
        self._writer: Writer | None = None
        self._tmp = self.path.with_name(self.path.name + ".part")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._last_tick, self._epoch_ns = -1, 0
        self._t0: float | None = None
        self._state = ""
        self._reason: str | None = None
        self._last_params: GaitParams | None = None
        self._last_imu: float | None = None
        self._now_ns = 0
        self.error: str | None = None
        self.messages = 0

    # -- the file ------------------------------------------------------------------------
    def open(self) -> McapRecorder:
        """Create the file (written to NAME.mcap.part, renamed when finished)."""
        try:
            self._file = self._tmp.open("wb")
        except OSError as e:
            raise ConfigError(f"--record {self.path}: cannot write it: "
                              f"{e.strerror or e}") from None
        self._writer = Writer(self._file, chunk_size=CHUNK_BYTES,
                              compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library="biped")
        self._writer.add_metadata("biped", {"take_header": json.dumps(self.header.as_json())})
        for name in ROS_TYPES:
            text, _ = self._store.generate_msgdef(name, ros_version=2)
            self._schemas[name] = self._writer.register_schema(name, "ros2msg", text.encode())
        self._schemas["foxglove.Log"] = self._writer.register_schema(
            "foxglove.Log", "jsonschema", json.dumps(LOG_SCHEMA).encode())
        params = {"title": "biped.GaitParams", "type": "object",
                  "properties": {k: {"type": "number"} for k in GaitParams().as_dict()}}
        self._schemas["biped.GaitParams"] = self._writer.register_schema(
            "biped.GaitParams", "jsonschema", json.dumps(params).encode())
        return self

    def close_quietly(self) -> str | None:
        """Finish the file (summary and index) and rename it into place; the first failed
        write as one line, or None."""
        writer, file = self._writer, self._file
        self._writer = self._file = None
        if writer is None or file is None:
            return self.error
        try:
            writer.finish()
            file.close()
            self._tmp.replace(self.path)
        except OSError as e:
            self.error = self.error or f"{self.path}: {e.strerror or e}"
            file.close()
        return self.error

    # -- messages ------------------------------------------------------------------------
    def _channel(self, topic: str, schema: str) -> int:
        cid = self._channels.get(topic)
        if cid is None:
            assert self._writer is not None
            encoding = "json" if schema in ("foxglove.Log", "biped.GaitParams") else "cdr"
            cid = self._writer.register_channel(topic, encoding, self._schemas[schema])
            self._channels[topic] = cid
        return cid

    def _write(self, topic: str, schema: str, data: bytes) -> None:
        assert self._writer is not None
        self._writer.add_message(self._channel(topic, schema), log_time=self._now_ns,
                                 publish_time=self._now_ns, data=data)
        self.messages += 1

    def _ros(self, topic: str, kind: str, **fields: Any) -> None:
        msg = self._store.types[kind](**fields)
        self._write(topic, kind, bytes(self._store.serialize_cdr(msg, kind)))

    def _header(self, frame: str = "", *, stamp: int | None = None) -> Any:
        t = self._store.types
        ns = self._now_ns if stamp is None else stamp
        stamp_msg = t["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000,
                                                     nanosec=ns % 1_000_000_000)
        return t["std_msgs/msg/Header"](stamp=stamp_msg, frame_id=frame)

    def log(self, text: str, *, level: str = "info", name: str = "biped") -> None:
        """An event on ``/events`` at the last tick's time (before the first: now)."""
        if self._writer is None:
            return
        if not self._now_ns:
            self._now_ns = time.time_ns()
        sec, nsec = divmod(self._now_ns, 1_000_000_000)
        self._write("/events", "foxglove.Log", json.dumps({
            "timestamp": {"sec": sec, "nsec": nsec}, "level": LEVELS[level],
            "message": text, "name": name, "file": "", "line": 0}).encode())

    def __call__(self, tel: Telemetry) -> None:
        if self.error is not None:
            raise OSError(self.error)
        if self._writer is None or tel.tick == self._last_tick or not tel.q_cmd:
            if self._writer is not None and tel.state in ("stopped", "estop"):
                self._end(tel)
            return
        try:
            self._tick(tel)
        except OSError as e:
            self.error = self.error or f"{self.path}: {e.strerror or e}"
            raise

    def _end(self, tel: Telemetry) -> None:
        if self._state != tel.state:
            self._state = tel.state
            self.log(f"{tel.state}: {tel.stop_reason or 'completed'}",
                     level="error" if tel.state == "estop" else "info")

    def _tick(self, tel: Telemetry) -> None:
        self._last_tick = tel.tick
        if self._t0 is None:
            self._t0, self._epoch_ns = tel.t, time.time_ns()
        self._now_ns = self._epoch_ns + int(round((tel.t - self._t0) * 1e9))
        if tel.state != self._state:
            self._state = tel.state
            self.log(f"state: {tel.state}")
        if tel.stop_reason and tel.stop_reason != self._reason:
            self._reason = tel.stop_reason
            self.log(f"stop: {tel.stop_reason}", level="warning")
        empty = np.empty(0)
        self._ros("/joint_commands", "sensor_msgs/msg/JointState", header=self._header(),
                  name=self.names, position=np.asarray(tel.q_cmd, dtype=np.float64),
                  velocity=empty, effort=empty)
        if tel.fresh and tel.q_present is not None:
            self._read_back(tel)
        if tel.imu is not None and tel.imu.t != self._last_imu:
            self._imu(tel)
        if self._body is not None:
            pos, quat = self._body.base_pose()
            t = self._store.types
            pose = t["geometry_msgs/msg/Pose"](
                position=t["geometry_msgs/msg/Point"](x=float(pos[0]), y=float(pos[1]),
                                                      z=float(pos[2])),
                orientation=t["geometry_msgs/msg/Quaternion"](
                    x=float(quat[1]), y=float(quat[2]), z=float(quat[3]), w=float(quat[0])))
            self._ros("/torso_pose", "geometry_msgs/msg/PoseStamped",
                      header=self._header("world"), pose=pose)
        params = self._params() if self._params is not None else None
        if params is not None and params is not self._last_params and params != self._last_params:
            self._last_params = params
            self._write("/gait/params", "biped.GaitParams", json.dumps(params.as_dict()).encode())

    def _read_back(self, tel: Telemetry) -> None:
        assert tel.q_present is not None
        loads = [tel.servo[i].load if i in tel.servo else None for i in self.ids]
        effort = np.array([math.nan if v is None else v / 100.0 * s
                           for v, s in zip(loads, self._stall, strict=True)])
        assert self._t0 is not None    # stamped when the reply was in (a take's present_t),
        replied = self._epoch_ns + int(round((tel.t_read - self._t0) * 1e9))  # loop's clock
        self._ros("/joint_states", "sensor_msgs/msg/JointState", header=self._header(stamp=replied),
                  name=self.names, position=np.asarray(tel.q_present, dtype=np.float64),
                  velocity=np.empty(0), effort=effort)
        for name, i in zip(self.names, self.ids, strict=True):
            s = tel.servo.get(i)
            if s is not None and s.temperature is not None:
                self._ros("/servo_temperatures", "sensor_msgs/msg/Temperature",
                          header=self._header(name), temperature=float(s.temperature),
                          variance=0.0)

    def _imu(self, tel: Telemetry) -> None:
        s = tel.imu
        assert s is not None
        self._last_imu = s.t
        t = self._store.types
        vec = t["geometry_msgs/msg/Vector3"]
        w, x, y, z = s.quat if s.quat is not None else (1.0, 0.0, 0.0, 0.0)
        unknown = np.zeros(9)
        orientation_cov = unknown.copy()
        if s.quat is None:            # REP 145: -1 first: no orientation estimate
            orientation_cov[0] = -1.0
        self._ros("/imu", "sensor_msgs/msg/Imu", header=self._header("torso"),
                  orientation=t["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
                  orientation_covariance=orientation_cov,
                  angular_velocity=vec(x=s.gyro[0], y=s.gyro[1], z=s.gyro[2]),
                  angular_velocity_covariance=unknown,
                  linear_acceleration=vec(x=s.accel[0], y=s.accel[1], z=s.accel[2]),
                  linear_acceleration_covariance=unknown)


class Alongside:
    """A take and its MCAP side by side (panel takes, ``--mcap``); the take's error first."""

    def __init__(self, take: Any, mcap: McapRecorder) -> None:
        self.take, self.mcap = take, mcap

    def open(self) -> Alongside:
        self.take.open()
        try:
            self.mcap.open()
        except BaseException:
            self.take.close_quietly()
            raise
        return self

    def __call__(self, tel: Telemetry) -> None:
        self.take(tel)
        self.mcap(tel)

    def close_quietly(self) -> str | None:
        first, second = self.take.close_quietly(), self.mcap.close_quietly()
        return first or second
