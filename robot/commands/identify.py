"""`biped identify`: a servo model from pendulum logs, and how well a model predicts them.

  biped identify fit LOGS... --motor NAME --out model.toml
      fits the servo model's motor, gearbox and firmware-scale parameters to the logs
      (Optuna's CMA-ES sampler), holding out a share of the logs; prints the train and
      held-out error and writes a model file a robot file can name (servo_file).
  biped identify check LOG... --model NAME|FILE [--plot out.png] [--json]
      replays each log closed loop from its first recorded state in the MuJoCo servo model
      and prints the mean |q_sim - q_log| per log and overall (logs resampled to 5 ms).

  biped identify record --bus K --port P --id N --motor NAME --mass KG --length M --out DIR
      runs a real servo with a weight on an arm through sines, a chirp, steps and a
      lift-and-drop at each --kp and writes one log per run (robot/commands/identify_record.py).

Logs are the public pendulum-log JSON format (robot/servo/pendulum_log.py; .json or
.json.gz): a servo swinging a known weight on an arm (docs/servos.md says how to build one).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from robot.commands.common import (
    bounded_float,
    checked,
    input_file,
    one_line_errors,
    output_file,
    plot_output,
)
from robot.commands.identify_record_cli import add_record_parser, run_record_command
from robot.config.servo_file import load_servo_file, physics_for, servo_file_text
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.servo.models import MODELS
from robot.servo.pendulum_log import PendulumLog, read_log, split_logs
from robot.servo.physics import FITTED, ServoPhysics


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = subparsers.add_parser("identify", help="fit or check a servo model on pendulum logs",
                              description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    fit = one_line_errors(sub.add_parser("fit", help="fit a servo model to pendulum logs"))
    fit.add_argument("logs", nargs="+", metavar="LOG", help="pendulum logs (.json, .json.gz)")
    fit.add_argument("--motor", required=True, metavar="NAME",
                     help=f"the servo model the logs are of: {', '.join(MODELS)}")
    fit.add_argument("--out", required=True, metavar="FILE", help="model file to write (.toml)")
    fit.add_argument("--holdout", type=bounded_float(0.0, 0.5, "", what="a share"),
                     default=0.25, metavar="SHARE",
                     help="share of the logs held out of the fit (default 0.25; 0: none)")
    fit.add_argument("--trials", type=int, default=1500, metavar="N",
                     help="CMA-ES evaluations (default 1500)")
    fit.add_argument("--params", default=None, metavar="A,B",
                     help=f"parameters to fit (default: all but max_velocity and kd_scale; "
                          f"valid: {', '.join(FITTED)})")
    fit.add_argument("--seed", type=int, default=0, help="sampler seed (default 0)")
    fit.add_argument("--keep-stall", action="store_true",
                     help="keep the model's stall torque (the resistance follows kt): for "
                          "logs that never drive the servo to full duty")
    check = one_line_errors(sub.add_parser("check", help="replay logs in the servo model"))
    check.add_argument("logs", nargs="+", metavar="LOG", help="pendulum logs (.json, .json.gz)")
    check.add_argument("--model", required=True, metavar="NAME|FILE",
                       help="a servo model name (its bundled model) or a model file")
    check.add_argument("--plot", default=None, metavar="PNG",
                       help="plot goal, recorded and simulated position per log")
    check.add_argument("--json", action="store_true", help="print one JSON object")
    add_record_parser(sub)
    for q in (fit, check):
        q.add_argument("--offset", type=bounded_float(-0.5, 0.5, "rad", what="an offset"),
                       default=0.0, metavar="RAD",
                       help="the rig's mounting offset: gravity acts on q + RAD (default 0)")
    return one_line_errors(p)


def _logs(paths: list[str], law: str) -> list[PendulumLog]:
    """The logs, each checked (robot.servo.log_rules) for a servo of firmware ``law``."""
    return [read_log(checked("LOG", input_file, p), law=law) for p in paths]


def _model(text: str) -> ServoPhysics:
    if text in MODELS:
        return physics_for(text)
    if text.endswith(".toml") or "/" in text:
        return load_servo_file(checked("--model", input_file, text))
    raise ConfigError(f"--model: expected a servo model ({', '.join(MODELS)}) or a model "
                      f"file (.toml), got {text!r}")


def _errors(logs: list[PendulumLog], physics: ServoPhysics, offset: float,
            plot: str | None = None) -> list[float]:
    from sim.mujoco.pendulum import PendulumBench

    bench = PendulumBench(logs, MODELS[physics.name])
    simulated = bench.replay(physics, offset=offset)
    if plot is not None:
        from robot.commands.identify_plot import plot_replays

        plot_replays(bench.logs, simulated, plot, title=f"{physics.name} servo model")
    return [float(e) for e in bench.errors(simulated)[0]]


def _check(args: argparse.Namespace) -> int:
    if args.plot is not None:
        checked("--plot", plot_output, args.plot)
    physics = _model(args.model)
    logs = _logs(args.logs, physics.law)
    errors = _errors(logs, physics, args.offset, args.plot)
    mean = sum(errors) / len(errors)
    if args.json:
        print(json.dumps({"mean_error_rad": mean, "model": physics.name,
                          "logs": [{"file": log.source, "mean_error_rad": e}
                                   for log, e in zip(logs, errors, strict=True)]}))
        return 0
    for log, e in zip(logs, errors, strict=True):
        print(f"{log.source}: {e:.4f} rad  (kp {log.kp}, {log.vin:g} V, {log.trajectory})")
    print(f"mean |q_sim - q_log| over {len(logs)} logs: {mean:.4f} rad ({physics.name})")
    if args.plot is not None:
        print(f"plot: {args.plot}")
    return 0


def _fit(args: argparse.Namespace) -> int:
    from sim.mujoco.fit import DEFAULT_PARAMS, fit_physics

    if args.motor not in MODELS:
        raise ConfigError(f"--motor: expected one of {', '.join(MODELS)}, got {args.motor!r}")
    out = Path(checked("--out", output_file, args.out))
    params = tuple(args.params.split(",")) if args.params else DEFAULT_PARAMS
    bad = sorted(set(params) - set(FITTED))
    if bad:
        raise ConfigError(f"--params: {bad[0]} is not a fitted parameter; valid: {', '.join(FITTED)}")
    if args.trials < 10:
        raise ConfigError(f"--trials: expected at least 10, got {args.trials}")
    train_paths, held_paths = split_logs([Path(p) for p in args.logs], args.holdout)
    if not train_paths:   # one log, all of it held out
        raise ConfigError("need at least 2 logs with --holdout > 0 (or --holdout 0)")
    start = physics_for(args.motor)
    train = _logs([str(p) for p in train_paths], start.law)
    held = _logs([str(p) for p in held_paths], start.law)
    source = f"fitted by biped identify fit on {len(train)} logs ({', '.join(p.name for p in train_paths)})"
    print(f"fitting {', '.join(params)} of {args.motor} on {len(train)} logs "
          f"({len(held)} held out), {args.trials} trials ...")
    result = fit_physics(train, MODELS[args.motor], start, params=params, trials=args.trials,
                         seed=args.seed, offset=args.offset, keep_stall=args.keep_stall,
                         source=source)
    train_err = _errors(train, result.physics, args.offset)
    held_err = _errors(held, result.physics, args.offset) if held else []
    fit = {"train_error_rad": sum(train_err) / len(train_err), "trials": result.trials,
           "train_logs": [p.name for p in train_paths], "held_out_logs": [p.name for p in held_paths]}
    if held_err:
        fit["held_out_error_rad"] = sum(held_err) / len(held_err)
    write_text(out, servo_file_text(result.physics, fit=fit, comment=(
        f"{args.motor} servo model fitted by `biped identify fit` (docs/servos.md).")))
    for path, e in zip([*train_paths, *held_paths], [*train_err, *held_err], strict=True):
        print(f"  {'held out' if path in held_paths else 'train   '} {path.name}: {e:.4f} rad")
    print(f"train error {fit['train_error_rad']:.4f} rad over {len(train)} logs")
    if held_err:
        print(f"held-out error {fit['held_out_error_rad']:.4f} rad over {len(held)} logs")
    print(f"wrote {out}")
    return 0


def run(args: argparse.Namespace) -> int:
    if args.action == "record":
        return run_record_command(args)
    return _fit(args) if args.action == "fit" else _check(args)
