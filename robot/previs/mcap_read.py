"""Reading back an MCAP run record (robot/loop/mcap_recorder.py): the joint streams as a
take (``biped sim-gap``) or as record rows (``biped plot``), with the ``mcap`` reader
and the CDR decoding of the ``rosbags`` type store."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from mcap.exceptions import McapError
from mcap.reader import make_reader
from rosbags.typesys import Stores, get_typestore

from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.motion.takes import Take, TakeHeader, header_of

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class McapRun:
    """header: the run's take header; t (n,) [s from the first command]; q (n, joints)
    [rad]: the commands; present (n, joints) [rad] and present_t (n,) [s, when the reply
    was in; t where none], load (n, joints) [N m], temperature
    (n, joints) [deg C]: the read-backs at the command tick they came with (NaN on the
    others); states (n,): the loop's state at each tick (from /events); events: (t [s],
    text) of every /events message."""

    header: TakeHeader
    t: Array
    q: Array
    present: Array
    present_t: Array
    load: Array
    temperature: Array
    states: tuple[str, ...]
    events: tuple[tuple[float, str], ...]


def read_mcap(path: str | Path) -> McapRun:
    """ConfigError (one line naming the file) if it is not an MCAP run record."""
    p = Path(path)
    store = get_typestore(Stores.ROS2_HUMBLE)
    try:
        with p.open("rb") as f:
            reader = make_reader(f)
            meta = {m.name: m.metadata for m in reader.iter_metadata()}
            if "biped" not in meta or "take_header" not in meta["biped"]:
                raise ConfigError(f"{p}: an MCAP file without biped's run header (record "
                                  "it with --record NAME.mcap)")
            header = header_of(f"{p}: take_header", json.loads(meta["biped"]["take_header"]))
            cmd: list[tuple[int, Any]] = []
            back: list[tuple[int, Any]] = []
            temps: list[tuple[int, str, float]] = []
            events: list[tuple[int, str]] = []
            for schema, channel, message in reader.iter_messages(
                    topics=["/joint_commands", "/joint_states", "/servo_temperatures",
                            "/events"]):
                if channel.topic == "/events":
                    events.append((message.log_time, json.loads(message.data)["message"]))
                    continue
                assert schema is not None
                msg: Any = store.deserialize_cdr(message.data, schema.name)
                if channel.topic == "/joint_commands":
                    cmd.append((message.log_time, msg))
                elif channel.topic == "/joint_states":
                    back.append((message.log_time, msg))
                else:
                    temps.append((message.log_time, msg.header.frame_id, msg.temperature))
    except FileNotFoundError:
        raise ConfigError(f"{p}: file not found") from None
    except (McapError, OSError, ValueError, KeyError, AssertionError) as e:
        raise ConfigError(f"{p}: not a readable MCAP run record: {e}") from None
    return _arrays(p, header, cmd, back, temps, events)


def _arrays(p: Path, header: TakeHeader, cmd: list[tuple[int, Any]],
            back: list[tuple[int, Any]], temps: list[tuple[int, str, float]],
            events: list[tuple[int, str]]) -> McapRun:
    if len(cmd) < 2:
        raise ConfigError(f"{p}: {len(cmd)} /joint_commands messages; a record needs 2")
    joints = list(header.joints)
    times = np.array([t for t, _ in cmd], dtype=np.int64)
    n, j = len(cmd), len(joints)
    q = np.array([m.position for _, m in cmd], dtype=np.float64)
    if q.shape != (n, j):
        raise ConfigError(f"{p}: /joint_commands: expected {j} positions a message")
    present, load, temp = (np.full((n, j), math.nan) for _ in range(3))
    t0 = int(times[0])
    replied = (times - t0) / 1e9
    row = {int(t): k for k, t in enumerate(times)}
    for t, m in back:
        k = row.get(int(t))
        if k is not None and len(m.position) == j:
            present[k] = m.position
            stamp = m.header.stamp
            replied[k] = (stamp.sec * 1_000_000_000 + stamp.nanosec - t0) / 1e9
            if len(m.effort) == j:
                load[k] = m.effort
    for t, name, value in temps:
        k = row.get(int(t))
        if k is not None and name in joints:
            temp[k, joints.index(name)] = value
    states, state, e = [], "", 0
    marks = sorted(events)
    for t in times:
        while e < len(marks) and marks[e][0] <= t:
            if marks[e][1].startswith("state: "):
                state = marks[e][1].removeprefix("state: ")
            e += 1
        states.append(state)
    return McapRun(header, (times - t0) / 1e9, q, present, replied, load, temp,
                   tuple(states), tuple(((t - t0) / 1e9, text) for t, text in marks))


def mcap_take(path: str | Path) -> Take:
    """The record as a take of its commands and read-backs (no timeline)."""
    run = read_mcap(path)
    return Take(header=run.header, changes={}, stop_tick=None, t=run.t, q=run.q,
                states=run.states, source=str(path), present=run.present,
                present_t=run.present_t)


def mcap_rows(path: str | Path) -> list[dict[str, Any]]:
    """The record as the rows of a `biped walk --record` file (robot/previs/plots.py)."""
    run = read_mcap(path)
    h = run.header
    try:              # loads back in % of the servo's maximum torque, as a CSV record has
        robot = load_robot(h.robot_file if Path(h.robot_file).is_file() else h.robot)
        stall = np.array([robot.servo(j).stall_torque for j in robot.joints])
        load = run.load / stall * 100.0 if len(stall) == run.load.shape[1] else run.load * math.nan
    except ConfigError:
        load = run.load * math.nan
    rows = []
    for k in range(len(run.t)):
        row: dict[str, Any] = {"t": float(run.t[k]), "state": run.states[k], "tick": k + 1}
        for name, arr in (("cmd_", run.q), ("present_", run.present),
                          ("temp_", run.temperature), ("load_", load)):
            row.update({f"{name}{j}": float(v) for j, v in zip(run.header.joints, arr[k],
                                                                strict=True)})
        rows.append(row)
    return rows
