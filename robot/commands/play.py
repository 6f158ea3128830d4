"""`biped play FILE`: replay a take (NAME.take.jsonl) or play a keyframe sequence
(.toml/.json) on any bus, through the same streaming loop and safety as `biped walk`.

A take replays its parameter timeline on the take's robot at the take's rate (with the
balance feedback if it was on), so in the simulation it reproduces the recorded joint
stream. A show take (`biped import`) streams its joints as authored, and where its timeline
has the gait walk, the gait walks the legs (robot/motion/show_walk.py; ``--no-root-travel``:
the authored legs everywhere). A keyframe sequence plays on its own: the joints it names
follow it, the others hold the standing pose. Either way: ramp in from the present pose,
clamp, slew, then ramp to rest and torque off (``--hold``: stay on). Ctrl-C / SIGTERM as for `biped walk`.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from robot.commands.balance_args import add_balance_args, imu_for
from robot.commands.chase_args import (
    add_chase_args,
    chase_events,
    chased,
    live,
    stop_when_lost,
    summary,
)
from robot.commands.common import (
    add_bus_args,
    audio_offset,
    bus_from,
    checked,
    input_file,
    output_file,
    params_from,
    plot_output,
    rate_hz,
    seconds,
)
from robot.commands.model_args import add_model_names_arg, model_for
from robot.commands.physics_check import physics_check, physics_watch
from robot.commands.show_args import add_show_args, show_options
from robot.commands.walk import servo_words
from robot.config.bundled import DEFAULT_GAIT
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.clock import MonotonicClock
from robot.loop.mcap_recorder import McapRecorder, is_mcap
from robot.loop.recorder import Recorder
from robot.loop.soundtrack import Soundtrack
from robot.loop.take_writer import TakeWriter
from robot.loop.telemetry import Telemetry
from robot.motion.keyframes import SUFFIXES, load_sequence, parse_sequence
from robot.motion.layered import LayeredEngine
from robot.motion.scripted import PlaybackEngine
from robot.motion.show import Cue, Show, show_of, show_of_sequence, stream_sequence
from robot.motion.show_walk import ShowEngine, Travel
from robot.motion.takes import SUFFIX, Take, TakeHeader, is_take, read_take
from robot.previs.show_check import plot_check
from robot.run.run import Run
from robot.run.spec import RunOptions, RunSpec
from robot.showctl.play_target import play_show_control


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("play", help="replay a take or play a keyframe sequence (any bus)",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("file", metavar="FILE", help=f"a take (NAME{SUFFIX}) or a keyframe "
                   "sequence (.toml/.json)")
    p.add_argument("--robot", default=None, metavar="NAME|PATH",
                   help="robot (default: the take's; for a sequence the default robot)")
    p.add_argument("--gait", default=DEFAULT_GAIT, help="sequence only: the standing pose's "
                   "gait preset (default: %(default)s)")
    add_bus_args(p, default="sim")
    p.add_argument("--rate", type=rate_hz, default=None,
                   help="sequence only: control rate [Hz] (a take plays at its own rate)")
    p.add_argument("--seconds", type=seconds, default=None,
                   help="sequence only: play this long (a looping sequence repeats)")
    p.add_argument("--hold", action="store_true", help="hold the rest pose with torque on")
    p.add_argument("--realtime", action="store_true", help="pace the simulation to the wall clock")
    p.add_argument("--view", action="store_true", help="open the MuJoCo viewer (needs a display)")
    p.add_argument("--record", default=None, metavar="PATH",
                   help=f"record the replay (.csv, .jsonl, .mcap or NAME{SUFFIX})")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--audio", default=None, type=input_file, metavar="SOUND",
                   help="play this soundtrack in sync (default: the file's own show.audio); "
                        "the sim then runs in real time")
    p.add_argument("--audio-offset", type=audio_offset, default=None, metavar="SECONDS",
                   help="show time [s] at which the audio starts (default: the file's, or 0)")
    p.add_argument("--player", default=None, metavar="CMD",
                   help="audio player reading a WAV on stdin (default: aplay, paplay, else "
                        "ffplay)")
    p.add_argument("--check-plot", default=None, type=plot_output, metavar="FILE.png",
                   help="sim bus: plot the physics check (support margin, torque by limb, "
                        "headroom per joint)")
    p.add_argument("--no-root-travel", action="store_true",
                   help="an imported take: play the legs as authored where the gait would "
                        "walk them")
    add_chase_args(p)
    add_balance_args(p)
    p.add_argument("--balance", action="store_true", help="an imported take (biped import): "
                   "the balance stage corrects the legs while the arms and head perform as "
                   "authored (needs the robot's [imu])")
    add_show_args(p, midi=False)
    add_model_names_arg(p)
    p.set_defaults(set=[])
    return p


def _take_robot(args: argparse.Namespace, take: Take) -> RobotConfig:
    h = take.header
    robot = load_robot(args.robot or (h.robot_file if Path(h.robot_file).is_file()
                                      else h.robot))
    if robot.joint_names != h.joints:
        raise ConfigError(f"{take.source}: recorded on {h.robot} with joints "
                          f"{', '.join(h.joints)}; {robot.source} has "
                          f"{', '.join(robot.joint_names)}")
    return robot


def run(args: argparse.Namespace) -> int:
    checked("FILE", input_file, args.file)
    if args.record:
        checked("--record", output_file, args.record)
    shows = show_options(args)            # OSC, cue list: checked before anything moves
    kind = args.bus or "sim"
    if kind != "sim" and (args.view or args.realtime):
        raise ConfigError("--view and --realtime apply to --bus sim only")
    engine: GaitEngine
    if is_take(args.file):
        if args.rate is not None or args.seconds is not None:
            raise ConfigError("--rate and --seconds apply to keyframe sequences; a take "
                              "plays at its own rate for its own length")
        take = read_take(args.file)
        robot = _take_robot(args, take)
        h = take.header
        layer = (parse_sequence(h.keyframes, robot, source=f"{take.source}: keyframes")
                 if h.keyframes else None)
        stop = take.stop_tick if take.stop_tick is not None else len(take.t)
        show = show_of(h.show, take.source)
        if show.stream:   # an imported animation: its joints as they are (--balance: legs)
            travel = Travel() if args.no_root_travel or args.chase else Travel.of_take(take)
            engine = (ShowEngine(robot, h.params, stream=stream_sequence(take), travel=travel)
                      if travel.walks else
                      LayeredEngine(robot, h.params, keyframes=stream_sequence(take),
                                    walk=False))
            args.no_balance = not args.balance
        else:
            args.no_balance = args.no_balance or not h.balance
            engine = PlaybackEngine(robot, h.params, changes=take.changes, blends=take.blends, stop_tick=stop,
                                    keyframes=layer)
        rate, read_every, limit = h.rate_hz, h.read_every, None
        header = h
    elif Path(args.file).suffix in SUFFIXES:
        if args.record and is_take(args.record) and not args.chase:
            raise ConfigError(f"--record {args.record}: a take records a walk's timeline; "
                              "record a sequence's playback as .csv or .jsonl (the sequence "
                              "file itself is what replays it)")
        robot = load_robot(args.robot) if args.robot else load_robot()
        seq = load_sequence(args.file, robot)
        gait, params = params_from(args)
        engine = LayeredEngine(robot, params, keyframes=seq, walk=False)
        args.no_balance = True  # standing still: nothing to balance with the gait's loop
        rate, read_every, limit = args.rate or 200.0, 10, args.seconds
        show = show_of_sequence(args.file)
        header = TakeHeader(robot=robot.name, robot_file=robot.source,
                            joints=robot.joint_names, rate_hz=rate, read_every=read_every,
                            gait=gait.name, params=params, bus=kind)
    else:
        raise ConfigError(f"FILE {args.file}: expected a take (NAME{SUFFIX}) or a keyframe "
                          f"sequence ({', '.join(SUFFIXES)})")
    model = model_for(args, robot)       # --model-names: checked before anything moves
    soundtrack = _soundtrack(args, show)
    if (soundtrack is not None or live(args.chase)) and kind == "sim":
        args.realtime = True          # the sound (a live timecode) runs in real time: so does the show
    options: dict[str, Any] = (
        {"realtime": args.realtime, "view": args.view} if kind == "sim" else {})
    bus = bus_from(args, robot, kind=kind, **options)
    imu = imu_for(args, robot, bus)
    chase = chased(args, engine, getattr(bus, "clock", None) or MonotonicClock())
    writer: TakeWriter | Recorder | McapRecorder | None = None
    if args.record:
        if chase is not None:      # what was played, as a stream (biped play replays it)
            header = replace(header, show=replace(show, stream=True).as_json())
        writer = (TakeWriter(args.record, header,
                             show_time=None if chase is None else lambda: chase.show_time)
                  if is_take(args.record)
                  else McapRecorder(args.record, robot, header, params=lambda: engine.params,
                                    body=bus) if is_mcap(args.record)
                  else Recorder(args.record, robot.joint_names, robot.ids, model=model))
    if soundtrack is not None and isinstance(writer, McapRecorder):
        soundtrack.on_cue = _logged(soundtrack.on_cue, writer)
    watch = physics_watch(bus)
    runs: list[Run[Any]] = []              # the run, once built: what the timecode stops
    lost = None if chase is None else stop_when_lost(chase, lambda why: runs[0].request_stop(why))
    events = (chase_events(chase, writer.log)
              if chase is not None and isinstance(writer, McapRecorder) else None)
    observers = [o for o in (watch, soundtrack, lost, events) if o is not None]
    if chase is not None and soundtrack is not None:
        soundtrack.clock = lambda: chase.show_time

    def observe(tel: Telemetry) -> None:
        for o in observers:
            o(tel)
    spec = RunSpec(robot=robot, source=chase or engine, bus=bus, imu=imu, recorder=writer,
                   observer=observe if observers else None,
                   options=RunOptions(rate_hz=rate, read_every=read_every, hold=args.hold,
                                      seconds=limit, signals=True, watch=watch is not None,
                                      stop_on_fall=watch is not None))
    playing = Run(spec)
    runs.append(playing)
    try:
        with playing:
            if isinstance(writer, TakeWriter) and isinstance(engine, PlaybackEngine):
                timeline = [(k, "blend", b) for k, b in take.blends.items()] + \
                    [(k, "set", c) for k, c in take.changes.items()]
                for k, kind_, step in sorted(timeline, key=lambda e: (e[0], e[1])):
                    writer.event(k, **{kind_: dict(step)})
                writer.event(stop, stop=True)
            clock = (lambda: chase.show_time) if chase is not None else lambda: engine.time
            with play_show_control(shows, playing, joints=tuple(robot.joint_names),
                                   take=Path(args.file).name, show_time=clock, rate_hz=rate,
                                   announce=lambda line: print(f"biped play: {line}",
                                                               file=sys.stderr, flush=True)):
                playing.stream()
    finally:
        if soundtrack is not None:
            soundtrack.close()
        if chase is not None:
            chase.close()
    done = playing.result
    stats, record_error, code = done.stats, done.record_error, done.exit_code
    result = {"file": args.file, "robot": robot.name, "bus": kind, "ticks": stats.ticks,
              "rate_hz": rate, "gait_seconds": engine.time, "overruns": stats.overruns,
              "stop_reason": stats.stop_reason, "fault": stats.fault,
              "holding": stats.holding, "torque": stats.torque, "balance": imu is not None,
              "record_error": record_error, "exit_code": code}
    if soundtrack is not None:
        result["audio"] = {"file": str(soundtrack.show.audio_path()),
                           "started_at_show_s": soundtrack.started_at, "warning": soundtrack.warning}
    if chase is not None:
        result["chase"] = {**summary(chase), "stopped": chase.ended or stats.stop_reason}
    metrics = done.metrics or {}
    if "distance_m" in metrics:      # the sim: where the robot went (a show that walks)
        result["walked"] = {k: metrics[k] for k in ("distance_m", "lateral_drift_m", "heading_change_deg")}
    check = physics_check(watch, robot, done.metrics)
    if check is not None and check.fell_at is not None:
        code = result["exit_code"] = max(code, 1)   # the show did not hold up: incomplete
    if check is not None:
        result["physics"] = check.as_dict()
        if args.check_plot:
            plot_check(check, args.check_plot, title=f"physics check: {args.file}")
    if args.json:
        print(json.dumps(result))
    else:
        print(f"played {args.file} on {robot.name} ({kind} bus): {stats.ticks} ticks at "
              f"{rate:g} Hz, {engine.time:.2f} s of motion, {stats.overruns} overruns; "
              f"stopped: {stats.stop_reason}; servos {servo_words(stats.torque)}")
        if "walked" in result:
            w = result["walked"]
            print(f"walked {w['distance_m']:+.3f} m forward, {w['lateral_drift_m']:+.3f} m "
                  f"left, heading {w['heading_change_deg']:+.1f} deg")
        if record_error:
            print(f"record FAILED: {record_error}")
        if check is not None:
            print(check.table())
            if args.check_plot:
                print(f"wrote {args.check_plot}")
    return code


def _logged(on_cue: Callable[[Cue], None] | None, log: McapRecorder) -> Callable[[Cue], None]:
    """``on_cue``, and each cue on the record's /events too."""
    def cue(c: Cue) -> None:
        log.log(f"cue {c.t:.3f} s: {c.name}")
        if on_cue is not None:
            on_cue(c)
    return cue


def _soundtrack(args: argparse.Namespace, show: Show) -> Soundtrack | None:
    """The show's soundtrack and cues (``--audio`` / ``--audio-offset`` override the
    file's), or None for a show with neither."""
    if args.audio is not None:
        show = replace(show, audio=str(Path(args.audio).resolve()))
    if args.audio_offset is not None:
        show = replace(show, audio_offset_s=args.audio_offset)
    if show.audio is None and not show.cues:
        return None

    def cue(c: Cue) -> None:
        if not args.json:
            print(f"cue {c.t:.2f} s: {c.name}", flush=True)
    return Soundtrack(show, on_cue=cue, player=args.player)
