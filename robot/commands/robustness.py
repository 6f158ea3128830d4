"""`biped robustness`: the perturbation suite (robot.tuning.robustness) in parallel processes, a
survival table with and without balance, and a PNG of it."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from robot.commands.common import (
    add_robot_args,
    add_set_arg,
    params_from,
    plot_output,
    positive_int,
    robot_from,
    seconds,
)
from robot.previs.figure_file import save_figure
from robot.tuning.robustness import (
    STRAIGHT_DEG,
    STRAIGHT_DRIFT,
    STRAIGHT_S,
    WALK_ON_SHARE,
    Outcome,
    check_seconds,
    conditions,
    run_suite,
    straightness,
    survival_table,
)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("robustness", help="walk under slopes, bumps, pushes, parameter "
                       "changes, latency, friction and mass, with and without balance (sim)",
                       description="Walk the gait in simulation under every condition of a "
                       "suite (slopes, bumps, pushes, live parameter changes, latency, "
                       "friction, mass), with and without balance feedback, in parallel "
                       "processes; print how many runs survived per condition group and "
                       "optionally plot it (--plot).")
    add_robot_args(p)
    add_set_arg(p)
    p.add_argument("--seconds", type=seconds, default=None,
                   help="gait seconds per run (default: 30, or 12 with --quick)")
    p.add_argument("--quick", action="store_true", help="a few conditions (CI-sized)")
    p.add_argument("--balance-only", action="store_true",
                   help="skip the open-loop runs (--no-balance)")
    p.add_argument("--jobs", type=positive_int, default=None,
                   help="parallel runs (default: the number of cores)")
    p.add_argument("--out", type=plot_output, default=None, metavar="PNG",
                   help="write the survival picture here")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    return p


def run(args: argparse.Namespace) -> int:
    gait, params = params_from(args, robot_from(args))   # validates names before any run
    secs = args.seconds if args.seconds is not None else (12.0 if args.quick else 30.0)
    conds = conditions(params, quick=args.quick)
    check_seconds(conds, secs)
    modes = (True,) if args.balance_only else (True, False)
    total = len(conds) * len(modes)
    done = [0]
    wall0 = time.perf_counter()

    def progress(o: Outcome) -> None:
        done[0] += 1
        state = "error" if o.fell is None else "FELL" if o.fell else "ok"
        if not args.json:
            print(f"[{done[0]:3d}/{total}] {o.condition.name:<34} "
                  f"{'balance' if o.balance else 'open loop':<9} {state}"
                  + (f": {o.error}" if o.error else ""), file=sys.stderr, flush=True)
    outcomes = run_suite(args.robot, gait.name, params, conds, seconds=secs,
                         balance_modes=modes, jobs=args.jobs, progress=progress)
    wall = time.perf_counter() - wall0
    table = survival_table(outcomes)
    if args.out:
        plot_survival(table, args.out, title=f"{args.robot}, gait {gait.name}, {secs:g} s runs")
    errors = [o for o in outcomes if o.fell is None]
    straight = straightness(outcomes)
    if args.json:
        print(json.dumps({
            "robot": args.robot, "gait": gait.name, "seconds": secs, "wall_s": wall,
            "groups": {g: {("balance" if b else "open_loop"): {"survived": ok, "runs": n}
                           for b, (ok, n) in row.items()} for g, row in table},
            "runs": [{"condition": o.condition.name, "group": o.condition.group,
                      "balance": o.balance, "fell": o.fell, "fell_at_s": o.fell_at_s,
                      "distance_m": o.distance_m, "speed_m_s": o.speed_m_s,
                      "heading_deg": o.heading_deg, "walk_on": o.condition.walk_on,
                      "stood": o.stood, "survived": o.survived, "error": o.error}
                     for o in outcomes],
            "walk_on_share": WALK_ON_SHARE,
            "straightness": {("balance" if b else "open_loop"): v
                             for b, v in straight.items()}}))
    else:
        print(format_table(table, modes))
        falls = [o for o in outcomes if o.balance and o.fell]
        if falls:
            print("fell with balance: " + "; ".join(
                f"{o.condition.name} at {o.fell_at_s:.1f} s" for o in falls))
        stood = [o for o in outcomes if o.balance and o.stood]
        if stood:
            print(f"stood (under {100 * WALK_ON_SHARE:g} % of the flat walk's speed) with "
                  "balance: " + "; ".join(f"{o.condition.name} {o.speed_m_s:.3f} m/s"
                                          for o in stood))
        for b, v in straight.items():
            print(f"flat {STRAIGHT_S:g} s, {'balance' if b else 'open loop'}: heading "
                  f"{v['heading_deg']:+.1f} deg, drift {v['drift_m']:+.3f} m = "
                  f"{100 * v['drift_ratio']:.1f} % of {v['distance_m']:.2f} m "
                  f"({'inside' if v['ok'] else 'OUTSIDE'} the goal: {STRAIGHT_DEG:g} deg, "
                  f"{100 * STRAIGHT_DRIFT:g} %)")
        print(f"{total} runs of {secs:g} s in {wall:.0f} s")
        if args.out:
            print(f"wrote {args.out}")
    return 1 if errors else 0


def format_table(table: Sequence[tuple[str, dict[bool, tuple[int, int]]]],
                 modes: Sequence[bool]) -> str:
    head = f"{'condition':<18}" + "".join(
        f"{'balance' if b else 'open loop':>12}" for b in modes)
    lines = [head, "-" * len(head)]
    for group, row in table:
        cells = "".join(f"{row[b][0]:>6d}/{row[b][1]:<5d}" if b in row else f"{'':>12}"
                        for b in modes)
        lines.append(f"{group:<18}{cells}")
    return "\n".join(lines)


def plot_survival(table: Sequence[tuple[str, dict[bool, tuple[int, int]]]], out: str | Path,
                  *, title: str) -> None:
    """Horizontal bars: survival [%] per condition group, balance on and off."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = [g for g, _ in table]
    fig, ax = plt.subplots(figsize=(8, 0.45 * len(groups) + 1.5))
    height = 0.38
    for k, (balance, colour) in enumerate(((True, "tab:green"), (False, "tab:gray"))):
        ys, xs = [], []
        for i, (_, row) in enumerate(table):
            if balance in row:
                ok, n = row[balance]
                ys.append(i + (k - 0.5) * height)
                xs.append(100.0 * ok / n if n else 0.0)
                # n/N beside every bar, so 0 % reads as "0 of N", not as a missing row
                ax.text(xs[-1] + 1.0, ys[-1], f"{ok}/{n}", va="center", fontsize=7)
        if ys:
            ax.barh(ys, xs, height=height, color=colour,
                    label="balance on" if balance else "open loop (--no-balance)")
    ax.set_yticks(range(len(groups)), groups)
    ax.invert_yaxis()
    ax.set_xlim(0, 108)
    ax.set_xlabel("survived [% of runs]")
    ax.set_title(title, loc="left", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, out)
    plt.close(fig)
