"""`biped robustness --push-map`: the push map (robot.tuning.push_map) printed as a table
per balance mode (rows: phases, columns: directions; survived / 1-step limit [N*s]), as
one JSON object, and as polar plots (one per quarter of the cycle)."""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from robot.config.gait_file import Gait
from robot.config.params import GaitParams
from robot.config.world import PUSH_AT_S
from robot.previs.figure_file import save_figure
from robot.tuning.push_map import (
    DIRECTIONS_DEG,
    PHASES,
    QUICK_AT_S,
    QUICK_DIRECTIONS,
    QUICK_PHASES,
    QUICK_RESOLUTION_N_S,
    RESOLUTION_N_S,
    Cell,
    push_map,
)

#: The goal of issue 32: every cell at least this share of its 1-step limit, the median
#: at least GOAL_MEDIAN.
GOAL_EVERY = 0.8
GOAL_MEDIAN = 0.9


def _floats(text: str, lo: float, hi: float, what: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or not all(lo <= v < hi for v in values):
        raise argparse.ArgumentTypeError(f"expected {what} in [{lo:g}, {hi:g}), "
                                         f"comma-separated, got {text!r}")
    return tuple(dict.fromkeys(values))


def directions(text: str) -> tuple[float, ...]:
    """--directions: degrees, 0 forward, 90 left."""
    return _floats(text, 0.0, 360.0, "directions [deg]")


def phases(text: str) -> tuple[float, ...]:
    """--phases: fractions of the gait cycle."""
    return _floats(text, 0.0, 1.0, "phases of the cycle")


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--push-map", action="store_true",
                   help="instead of the suite: the largest push survived per direction and "
                        "phase (bisection to 0.05 N*s) against the robot's capture limit")
    p.add_argument("--directions", type=directions, default=None, metavar="DEG,DEG,...",
                   help="--push-map: push directions [deg], 0 forward, 90 left "
                        "(default: every 45)")
    p.add_argument("--phases", type=phases, default=None, metavar="P,P,...",
                   help="--push-map: phases of the cycle [0, 1) (default: 16)")


def run_map(args: argparse.Namespace, gait: Gait, params: GaitParams) -> int:
    quick = bool(args.quick)
    dirs = args.directions or (QUICK_DIRECTIONS if quick else DIRECTIONS_DEG)
    phs = args.phases or (QUICK_PHASES if quick else PHASES)
    modes = (True,) if args.balance_only or quick else (True, False)
    res = QUICK_RESOLUTION_N_S if quick else RESOLUTION_N_S
    at = QUICK_AT_S if quick else PUSH_AT_S
    wall0 = time.perf_counter()
    count = [0]

    def progress(c: Cell) -> None:
        count[0] += 1
        if not args.json:
            print(f"[{count[0]:3d}/{len(dirs) * len(phs) * len(modes)}] "
                  f"{'balance' if c.balance else 'open loop':<9} phase {c.phase:.4f} "
                  f"{c.direction_deg:5.1f} deg: {c.survived_n_s:.2f} N*s "
                  f"(1-step limit {c.limit_n_s.get(1, 0.0):.2f})", file=sys.stderr, flush=True)
    cells = push_map(args.robot, gait.name, params, directions=dirs, phases=phs,
                     balance_modes=modes, jobs=args.jobs, resolution=res, at_s=at,
                     progress=progress)
    wall = time.perf_counter() - wall0
    if args.out:
        plot_map(cells, args.out, title=f"{args.robot}, gait {gait.name}")
    summary = {("balance" if b else "open_loop"): goal(cells, balance=b) for b in modes}
    if args.json:
        print(json.dumps({"robot": args.robot, "gait": gait.name, "resolution_n_s": res,
                          "push_at_s": at, "wall_s": wall, "goal": summary,
                          "cells": [c.as_dict() for c in cells]}))
        return 0
    for b in modes:
        print(format_map([c for c in cells if c.balance == b], dirs, phs,
                         title="balance" if b else "open loop"))
        g = summary["balance" if b else "open_loop"]
        print(f"share of the 1-step limit: least {g['least']:.0%}, median {g['median']:.0%} "
              f"(goal {GOAL_EVERY:.0%} in every cell, {GOAL_MEDIAN:.0%} median: "
              f"{'met' if g['met'] else 'not met'})\n")
    print(f"{len(cells)} cells in {wall:.0f} s")
    if args.out:
        print(f"wrote {args.out}")
    return 0


def goal(cells: Sequence[Cell], *, balance: bool) -> dict[str, float | bool]:
    """The least and median share of the 1-step limit over a mode's cells (a cell with a
    0 limit counts as met), and whether issue 32's goal holds."""
    shares = [c.survived_n_s / c.limit_n_s[1] if c.limit_n_s.get(1, 0.0) > 0 else 1.0
              for c in cells if c.balance == balance]
    if not shares:
        return {"least": 0.0, "median": 0.0, "met": False}
    least, median = min(shares), statistics.median(shares)
    return {"least": least, "median": median,
            "met": least >= GOAL_EVERY and median >= GOAL_MEDIAN}


def format_map(cells: Sequence[Cell], dirs: Sequence[float], phs: Sequence[float], *,
               title: str) -> str:
    """Rows: phases; columns: directions; each cell survived / 1-step limit [N*s]."""
    at = {(c.phase, c.direction_deg): c for c in cells}
    head = f"{title + ': phase':<16}" + "".join(f"{d:>11g}" for d in dirs)
    lines = ["survived / 1-step limit [N*s], directions [deg] (0 forward, 90 left)",
             head, "-" * len(head)]
    for ph in phs:
        row = [at.get((ph, d)) for d in dirs]
        lines.append(f"{ph:<16.4f}" + "".join(
            f"{c.survived_n_s:>5.2f}/{c.limit_n_s.get(1, 0.0):<5.2f}" if c else f"{'':>11}"
            for c in row))
    return "\n".join(lines)


def plot_map(cells: Sequence[Cell], out: str | Path, *, title: str) -> None:
    """Four polar plots, one per quarter of the cycle: per phase the survived impulse
    (balance on: solid; open loop: dotted) and its 1-step limit (dashed) [N*s] against the
    push's direction (0 forward, 90 left)."""
    import math

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, subplot_kw={"projection": "polar"}, figsize=(16, 5.2))
    colours = plt.get_cmap("viridis")
    top = max([c.limit_n_s.get(1, 0.0) for c in cells] + [c.survived_n_s for c in cells]
              + [0.5])
    for q, ax in enumerate(axes):
        group = [c for c in cells if q / 4 <= c.phase < (q + 1) / 4]
        for k, ph in enumerate(sorted({c.phase for c in group})):
            colour = colours(k / 4)
            for balance, style in ((True, "-"), (False, ":")):
                row = sorted((c for c in group if c.phase == ph and c.balance == balance),
                             key=lambda c: c.direction_deg)
                if not row:
                    continue
                ang = [math.radians(c.direction_deg) for c in row]
                ang, surv = ang + ang[:1], [c.survived_n_s for c in row]
                ax.plot(ang, surv + surv[:1], style, color=colour, marker="o", ms=3,
                        label=f"phase {ph:.3f}" if balance else None)
                if balance:
                    lim = [c.limit_n_s.get(1, 0.0) for c in row]
                    ax.plot(ang, lim + lim[:1], "--", color=colour, lw=0.8)
        ax.set_theta_zero_location("N")          # forward up, left to the left
        ax.set_ylim(0, 1.05 * top)
        ax.set_title(f"phase {q / 4:g}-{(q + 1) / 4:g} of the cycle", fontsize=9)
        ax.tick_params(labelsize=7)
        if group:
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), fontsize=7, ncol=2)
    fig.suptitle(f"{title}: survived push [N*s] (solid: balance, dotted: open loop) and "
                 "the 1-step capture limit (dashed)", fontsize=10)
    fig.subplots_adjust(left=0.03, right=0.97, top=0.84, bottom=0.2, wspace=0.35)
    save_figure(fig, out, dpi=80)
    plt.close(fig)
