"""`biped tune`: gait and balance parameters found for the user's robot in simulation
(robot.tuning: Optuna over the robustness suite), written as a gait preset."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

from robot.commands.common import (
    add_robot_args,
    add_set_arg,
    bounded_float,
    bounded_int,
    output_file,
    params_from,
    parse_sets,
    positive_int,
    robot_from,
    seconds,
    writing,
)
from robot.config.bundled import DEFAULT_ROBOT, GAITS_DIR
from robot.config.gait_file import Gait
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError

#: --seed: the workers seed numpy's 32-bit generator with seed + 7919 x worker.
MAX_SEED = 2**31 - 1
seed = bounded_int(0, MAX_SEED, what="a seed")


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("tune", help="find gait and balance parameters that walk robustly "
                       "on this robot (sim, Optuna) and write them as a preset",
                       description="Search gait and balance parameters for this robot in "
                       "simulation (Optuna): each trial walks the robustness suite and is "
                       "scored by survival and walk quality. The best parameters are written "
                       "as a gait preset (--out) with a table against the starting preset, "
                       "the optimisation history and the parameter importance as PNGs. "
                       "--sensitivity only measures how much each parameter matters.")
    add_robot_args(p)
    add_set_arg(p)
    p.add_argument("--sensitivity", action="store_true",
                   help="do not tune: print how much each parameter moves the score "
                        "(+-20 %%, or a balance gain switched on), largest first")
    p.add_argument("--out", type=output_file, default=None, metavar="TOML",
                   help="the tuned preset to write (also NAME.history.png, "
                        "NAME.importance.png beside it)")
    p.add_argument("--trials", type=positive_int, default=40,
                   help="finished trials the study should hold (default: %(default)s; "
                        "a resumed study counts its earlier ones)")
    p.add_argument("--param", action="append", default=[], metavar="NAME[=LO:HI]",
                   help="search this parameter (repeatable; a pair such as Slgt sets "
                        "Slgt_R and Slgt_L; default range: the preset's value +-50 %%); "
                        "default: the set of docs/tuning.md")
    p.add_argument("--suite", choices=("quick", "full"), default="quick",
                   help="perturbations each trial must survive (biped robustness "
                        "[--quick]; default: %(default)s)")
    p.add_argument("--skip", action="append", default=[], metavar="GROUP",
                   help="leave a condition group out, e.g. 'push left' or 'push*' "
                        "(repeatable)")
    p.add_argument("--seconds", type=seconds, default=12.0,
                   help="gait seconds per run (default: %(default)s)")
    p.add_argument("--speed", type=bounded_float(0.01, 2.0, "m/s", what="a speed"),
                   default=None, metavar="M_S",
                   help="walking speed to aim for [m/s] (default: the starting preset's)")
    p.add_argument("--storage", default=None, metavar="URL",
                   help="Optuna storage (default: sqlite:///OUT.db beside --out); a "
                        "postgresql:// or mysql:// URL shares one study between machines")
    p.add_argument("--study", default=None, metavar="NAME",
                   help="study name (default: ROBOT-GAIT-OUT)")
    p.add_argument("--jobs", type=bounded_int(1, 256, what="a number of workers"), default=None,
                   help="worker processes (default: the number of cores)")
    p.add_argument("--seed", type=seed, default=1,
                   help=f"sampler seed, an integer in [0, {MAX_SEED}] (each worker adds its "
                        "number x 7919; numpy seeds are 32-bit)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    return p


def run(args: argparse.Namespace) -> int:
    import optuna

    from robot.tuning.objective import Setup, check_skip, suite_for
    from robot.tuning.progress import TrialProgress
    from robot.tuning.report import (
        WalkFigures,
        cadence,
        format_report,
        group_survival,
        plot_study,
        write_preset,
    )
    from robot.tuning.robustness import check_seconds
    from robot.tuning.space import search_space
    from robot.tuning.study import Plan, best_params, best_trial, references, run_study

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    robot = robot_from(args)
    gait, start = params_from(args, robot)
    if args.sensitivity:
        return sensitivity(args, start)
    if args.out is None:
        raise ConfigError("--out: required (the tuned preset to write), unless --sensitivity")
    knobs = tuple(search_space(args.param, start, hip_yaw=robot.has_hip_yaw,
                               robot_gait=robot.gait))
    out = Path(args.out)
    if out.suffix != ".toml":
        raise ConfigError(f"--out {args.out}: a gait preset is a .toml file")
    storage = args.storage or f"sqlite:///{out.with_suffix('.db')}"
    name = args.study or f"{robot.name}-{gait.name}-{out.stem}"
    jobs = args.jobs or os.cpu_count() or 1
    check_skip(tuple(args.skip), start, args.suite)
    setup = Setup(args.robot, args.suite, args.seconds, skip=tuple(args.skip))
    check_seconds(suite_for(setup, start), args.seconds)
    plan = Plan(storage, name, setup, start, knobs, args.trials, args.seed)
    wall0 = time.perf_counter()
    from robot.tuning.study import open_study

    study = open_study(plan)
    if not args.json:
        print(f"{name}: measuring the starting preset '{gait.name}' on the {args.suite} "
              "suite ...", file=sys.stderr, flush=True)
    setup, ref = references(study, setup, start, target_speed=args.speed,
                            made_for=made_for(args, gait, robot))
    plan = Plan(storage, name, setup, start, knobs, args.trials, args.seed)
    progress = TrialProgress(args.trials, quiet=args.json)
    t_study = time.perf_counter()
    study = run_study(plan, jobs=jobs, progress=progress)
    from robot.tuning.study import finished

    done = finished(study)
    progress(done)
    progress.close()
    study_s = time.perf_counter() - t_study
    best = best_params(study, plan)
    top = best_trial(study)
    best_score = top.value if top is not None else None
    start_score = float(ref["score"])
    groups = {c.name: c.group for c in suite_for(setup, start)}
    groups.update({c.name: c.group for c in suite_for(setup, best)})
    start_groups = group_survival(ref["runs"], groups)
    best_groups = group_survival(top.user_attrs["runs"], groups) if top else {}
    if top is not None and (top.value or 0.0) < ref["score"]:
        best, best_groups = start, start_groups       # never write something worse
        top = None
    with writing("--out", out):
        written = write_preset(out, best, name=out.stem,
                               description=f"tuned by biped tune for {robot.name} from "
                               f"'{gait.name}' ({done} trials, {args.suite} suite)")
        pngs = plot_study(study, out.with_suffix(""), start_score=start_score)
    wall = time.perf_counter() - wall0
    per_trial = study_s * jobs / max(1, done)
    result: dict[str, Any] = {
        "robot": robot.name, "gait": gait.name, "out": str(out), "study": name,
        "storage": storage, "trials": done, "wall_s": wall,
        "cpu_s_per_trial": per_trial, "start_survived": ref["survived"],
        "best_survived": best_groups and sum(ok for ok, _ in best_groups.values()),
        "runs_per_trial": ref["runs_total"], "best_score": best_score,
        "target_speed_m_s": setup.target_speed, "start_speed_m_s": ref.get("speed_m_s"),
        "best_speed_m_s": top.user_attrs.get("speed_m_s") if top else ref.get("speed_m_s"),
        "best_walking": bool(top.user_attrs.get("walking")) if top else None,
        "start_bumps_speed_m_s": ref.get("bumps_speed_m_s"),
        "best_bumps_speed_m_s": (top.user_attrs.get("bumps_speed_m_s") if top
                                 else ref.get("bumps_speed_m_s")),
        "start_cadence_steps_min": cadence(start), "best_cadence_steps_min": cadence(best),
        "start_crouch": start.stance, "best_crouch": best.stance,
        "knobs": {k.name: {"start": getattr(start, k.targets[0]),
                           "best": getattr(best, k.targets[0]), "lo": k.lo, "hi": k.hi}
                  for k in knobs},
        "groups": {g: {"start": start_groups.get(g), "best": best_groups.get(g)}
                   for g in dict.fromkeys([*start_groups, *best_groups])},
        "plots": [str(p) for p in pngs]}
    if args.json:
        print(json.dumps(result))
    else:
        print(format_report(knobs, start, written.params, start_score + 0.0, best_score,
                            start_groups, best_groups, walk=WalkFigures(
                                setup.target_speed, ref.get("speed_m_s"),
                                result["best_speed_m_s"], result["start_bumps_speed_m_s"],
                                result["best_bumps_speed_m_s"])))
        print(f"\nwrote {out} ({done} trials in {study_s:.0f} s on {jobs} workers: "
              f"{per_trial:.1f} s of one core per trial); plots: "
              + ", ".join(str(p) for p in pngs))
        print(f"resume or extend: the same command (study '{name}' in {storage})")
    return 0


def made_for(args: argparse.Namespace, gait: Gait, robot: RobotConfig
             ) -> tuple[str, GaitParams] | None:
    """Where the target speed is measured without --speed: a bundled preset on the
    bundled robot it was made for (the default robot: docs/gait.md), with the same --set;
    None (the robot being tuned) for the user's own preset or the default robot itself."""
    if args.speed is not None or Path(gait.source).parent != GAITS_DIR \
            or Path(robot.source) == DEFAULT_ROBOT:
        return None
    params = gait.for_robot(load_robot(DEFAULT_ROBOT))
    return str(DEFAULT_ROBOT), params.replace(parse_sets(args.set), where="--set")


def sensitivity(args: argparse.Namespace, start: Any) -> int:
    from tqdm import tqdm

    from robot.tuning.objective import Setup, check_skip, suite_for
    from robot.tuning.robustness import check_seconds
    from robot.tuning.sensitivity import format_sensitivity, study

    check_skip(tuple(args.skip), start, args.suite)
    setup = Setup(args.robot, args.suite, args.seconds, speed_or(args), skip=tuple(args.skip))
    check_seconds(suite_for(setup, start), args.seconds)
    bar = tqdm(desc="evaluations", unit="eval", file=sys.stderr, disable=args.json or None)

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)
    base, rows = study(setup, start, jobs=args.jobs or os.cpu_count() or 1,
                       progress=progress)
    bar.close()
    if args.json:
        print(json.dumps({"start_score": base, "knobs": [r._asdict() for r in rows]}))
    else:
        print(format_sensitivity(base, rows))
    return 0


def speed_or(args: argparse.Namespace) -> float | None:
    return float(args.speed) if args.speed is not None else None
