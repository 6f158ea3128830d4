"""A walk as `biped walk` runs it, from plain values (no argparse): its IMU, its engine
and recorder, its spec and its JSON summary. The CLI and the tuner (robot.tuning) build
walks here, so a tuned walk is the walk a user runs."""

from __future__ import annotations

import dataclasses
import logging
import math
from typing import Any

from robot.bus.base import Bus
from robot.config.model_angles import ModelAngles
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.imu import Imu, open_imu
from robot.loop.mcap_recorder import McapRecorder, is_mcap
from robot.loop.recorder import Recorder
from robot.loop.take_writer import TakeWriter
from robot.motion.keyframes import Sequence
from robot.motion.layered import LayeredEngine
from robot.motion.scripted import RecordingEngine
from robot.motion.takes import TakeHeader, is_take
from robot.run.result import RunResult
from robot.run.spec import Recording, RunOptions, RunSpec
from robot.run.switching import PresetSwitch, PresetSwitcher

log = logging.getLogger(__name__)


def walk_imu(robot: RobotConfig, bus: Bus, *, balance: bool = True,
             noise: float | None = None) -> Imu | None:
    """The robot's IMU (not opened) when balance is on, else None; ``noise``: scale of a
    simulated IMU's datasheet noise and offsets (None: the robot file's)."""
    if not balance or robot.imu is None:
        if robot.imu is None and balance:
            log.info("%s has no [imu]: walking open loop", robot.name)
        return None
    config = robot.imu
    if config.kind == "sim" and bus.kind != "sim":
        # The bundled robots simulate their IMU: on real servos there is none to read.
        log.warning("%s: imu.kind is \"sim\", which only exists in simulation: walking open "
                    "loop on the %s bus (set [imu] kind to your device, docs/imu.md)",
                    robot.source, bus.kind)
        return None
    if noise is not None:
        if config.kind != "sim":
            raise ConfigError(f"--imu-noise applies to a simulated IMU; {robot.source}: "
                              f"imu.kind is {config.kind!r}")
        config = dataclasses.replace(config, noise=noise, bias=noise)
    return open_imu(config, bus=bus)


def walk_spec(robot: RobotConfig, params: GaitParams, bus: Bus, *, gait: str,
              imu: Imu | None = None, keyframes: Sequence | None = None,
              record: str | None = None, options: RunOptions | None = None,
              switches: tuple[PresetSwitch, ...] = (),
              model: ModelAngles | None = None) -> RunSpec[GaitEngine]:
    """The run of a walk with ``params`` (preset ``gait``, for a take's header), a
    keyframe layer on the arms, a recording (NAME.take.jsonl: the parameter
    timeline; .csv or .jsonl: the joint stream; .mcap: the run's channels,
    robot.loop.mcap_recorder) and preset ``switches`` (blended live,
    robot.run.switching; a take records them as blends); ``model``: a .csv or .jsonl
    record adds the joints in the model's terms (robot.loop.recorder)."""
    options = options or RunOptions()
    recorder: Recording | None = None
    engine: GaitEngine
    header = TakeHeader(
        robot=robot.name, robot_file=robot.source, joints=robot.joint_names,
        rate_hz=options.rate_hz, read_every=options.read_every, gait=gait,
        params=params, bus=bus.kind, balance=imu is not None,
        keyframes=keyframes.as_json() if keyframes else None)
    if record and is_take(record):
        take = TakeWriter(record, header)
        engine = RecordingEngine(robot, params, sink=take.event, keyframes=keyframes)
        recorder = take
    else:
        engine = (LayeredEngine(robot, params, keyframes=keyframes) if keyframes
                  else GaitEngine(robot, params))
        if record and is_mcap(record):
            source = engine
            recorder = McapRecorder(record, robot, header, params=lambda: source.params,
                                    body=bus)
        elif record:
            recorder = Recorder(record, robot.joint_names, robot.ids, model=model)
    return RunSpec(robot=robot, source=engine, bus=bus, options=options, imu=imu,
                   recorder=recorder,
                   observer=PresetSwitcher(engine, switches) if switches else None)


#: A walk whose heading changes by more than this [deg per minute of the run] beyond what
#: its ``turn`` asked for is flagged in its summary (``heading_drifts``).
HEADING_DRIFT_DEG_MIN = 10.0


def walk_summary(spec: RunSpec[GaitEngine], result: RunResult, *,
                 gait: str) -> dict[str, Any]:
    """The JSON object of `biped walk --json`: robot, gait, bus, seconds, balance, then
    the result (RunResult.as_dict) and, where the bus measured the heading (simulation),
    the heading the gait asked for, the drift beyond it per minute and whether that is
    more than ``HEADING_DRIFT_DEG_MIN``; the time [s, at the loop's rate] the IK met an
    unreachable target (``ik_unreachable_s``) and each joint was held at a limit
    (``clamped_joints_s``: only those that were) and asked faster than its servo turns, so
    that the loop held it to the servo's speed (``speed_limited_joints_s``: only those that
    were); where the bus counted the feet on the
    ground (simulation), the flight time per gait cycle (``flight_s_per_cycle``); the
    preset switches made (``switches``)."""
    out = {"robot": spec.robot.name, "gait": gait, "bus": spec.bus.kind,
           "seconds": spec.options.seconds, "balance": spec.imu is not None,
           **result.as_dict()}
    if isinstance(spec.observer, PresetSwitcher):
        out["switches"] = spec.observer.as_list()
    feet = out.get("feet")
    if isinstance(feet, dict) and "flight_share" in feet:   # the sim's: per gait cycle
        out["flight_s_per_cycle"] = feet["flight_share"] * spec.source.params.cycle_s
    engine, rate = spec.source, result.stats.rate_hz
    out["ik_unreachable_s"] = engine.unreachable_ticks / rate if rate else 0.0
    out["clamped_joints_s"] = {name: n / rate for name, n in
                               zip(spec.robot.joint_names, engine.clamp_ticks, strict=True)
                               if n and rate}
    slewed = result.stats.slew_limited or (0,) * len(spec.robot.joint_names)
    out["speed_limited_joints_s"] = {name: n / rate for name, n in
                                     zip(spec.robot.joint_names, slewed, strict=True) if n and rate}
    ran_min = result.stats.ticks / result.stats.rate_hz / 60.0 if result.stats.rate_hz else 0.0
    if "heading_change_deg" in out and ran_min > 0.0:
        asked = math.degrees(engine.asked_yaw)
        drift = (float(out["heading_change_deg"]) - asked) / ran_min
        out.update({"heading_asked_deg": asked, "heading_drift_deg_min": drift,
                    "heading_drifts": abs(drift) > HEADING_DRIFT_DEG_MIN})
    return out
