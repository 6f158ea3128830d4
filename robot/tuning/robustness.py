"""The robustness suite: simulated walks under perturbations, with and without balance.

Each condition is one ``biped walk --json`` run (``robot.cli.main``: the same code path a
user runs, so the suite measures the product, not a copy of it), in a pool of worker
processes, one per core, each running one walk after the other (no interpreter start
and imports per run). A condition survives when the walk does not fall (sim.mujoco.metrics: torso low or
tilted past the fall threshold) in ``seconds`` of gait.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import math
import multiprocessing
import os
import sys
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Any

from robot.config.params import SPECS, GaitParams

#: Push impulse of the full suite [N*s] (issue 10's goal) and the gait time of the first
#: push [s]: well after the ramp-in.
PUSH_NS = 1.0
PUSH_AT_S = 8.0
#: Phases of the step at which pushes land (fractions of a gait cycle).
PUSH_PHASES = (0.0, 0.25, 0.5, 0.75)
#: Parameters the +/-20 % conditions change: every non-zero parameter of the preset that
#: shapes the motion (steering and balance gains are covered by their own conditions).
PARAM_SCALE = 0.2
SKIP_PARAMS = frozenset({"speed", "turn", "side_step", "ramp_cycles", "rig_leg", "fps"})


#: The straightness goal's walk [s]: heading within STRAIGHT_DEG and lateral drift within
#: STRAIGHT_DRIFT of the distance over this long on flat ground.
STRAIGHT_S = 60.0
STRAIGHT_DEG = 5.0
STRAIGHT_DRIFT = 0.05
#: Scales of the sim IMU's datasheet noise and offsets (every run has x1, the robot
#: file's "realistic" BNO055).
IMU_NOISE = (2.0, 3.0)


@dataclass(frozen=True)
class Condition:
    """One perturbation: a name, a group (one bar of the picture) and walk options;
    seconds: this condition's walk [s] (None: the suite's)."""

    group: str
    name: str
    args: tuple[str, ...] = ()
    seconds: float | None = None


@dataclass
class Outcome:
    """The result of one condition with balance on or off."""

    condition: Condition
    balance: bool
    fell: bool | None                      # None: the run failed (error set)
    fell_at_s: float | None = None
    distance_m: float = 0.0
    heading_deg: float = 0.0
    error: str = ""
    summary: dict[str, Any] = field(default_factory=dict)


def conditions(params: GaitParams, *, quick: bool = False) -> list[Condition]:
    """The suite for a preset with ``params`` (``quick``: a few cases for CI)."""
    cycle = params.cycle_s
    out = [Condition("flat", "flat")]
    slopes = (5.0, -5.0) if quick else (2.0, 5.0, -2.0, -5.0)
    out += [Condition("slope", f"slope {s:+g} deg", ("--slope", f"{s:g}")) for s in slopes]
    crosses = (4.0,) if quick else (4.0, -4.0)
    out += [Condition("cross slope", f"cross slope {s:+g} deg", ("--cross-slope", f"{s:g}"))
            for s in crosses]
    heights, seeds = ((5.0,), (0,)) if quick else ((1.0, 3.0, 5.0), (0, 1, 2))
    out += [Condition("bumps", f"bumps {h:g} mm seed {s}",
                      ("--bumps", f"{h:g}", "--terrain-seed", str(s)))
            for h in heights for s in seeds]
    phases = (0.0,) if quick else PUSH_PHASES
    pushes = {"forward": (1, 0), "backward": (-1, 0), "left": (0, 1), "right": (0, -1)}
    for direction, (ux, uy) in pushes.items():
        for ph in phases:
            t = PUSH_AT_S + ph * cycle
            out.append(Condition(f"push {direction}",
                                 f"push {PUSH_NS:g} N*s {direction} at phase {ph:g}",
                                 ("--push", f"{t:.3f}:{ux * PUSH_NS:g},{uy * PUSH_NS:g}")))
    if not quick:
        out += scaled_params(params)
    for ms in ((20.0,) if quick else (10.0, 20.0)):
        out.append(Condition("latency", f"latency {ms:g} ms", ("--latency", f"{ms:g}")))
    for scale in (IMU_NOISE[-1:] if quick else IMU_NOISE):
        out.append(Condition("imu noise", f"imu noise x{scale:g}", ("--imu-noise", f"{scale:g}")))
    if not quick:
        out.append(Condition("flat 60 s", f"flat {STRAIGHT_S:g} s", seconds=STRAIGHT_S))
        out += [Condition("friction", f"friction x{f:g}", ("--friction", f"{f:g}"))
                for f in (0.5, 2.0)]
        out += [Condition("mass", f"mass x{m:g}", ("--mass-scale", f"{m:g}"))
                for m in (0.8, 1.2)]
    return out


#: A push needs this long after it [s] to tell a recovery from a slow fall.
AFTER_PUSH_S = 2.0


def check_seconds(conds: Iterable[Condition], seconds: float) -> None:
    """Refuse runs too short for the latest push to land and be recovered from."""
    from robot.errors import ConfigError

    last = max((float(c.args[c.args.index("--push") + 1].split(":")[0])
                for c in conds if "--push" in c.args and c.seconds is None), default=None)
    if last is not None and seconds < last + AFTER_PUSH_S:
        raise ConfigError(f"--seconds {seconds:g}: the suite's pushes land up to "
                          f"{last:.2f} s into the gait; give at least "
                          f"{last + AFTER_PUSH_S:.1f} s (or leave the pushes out)")


def scaled_params(params: GaitParams) -> list[Condition]:
    """Every shaping parameter of ``params`` +/- PARAM_SCALE, clipped to its documented
    range (a clipped change is named; one that the range leaves at the preset's value is
    left out)."""
    out = []
    for name, v in params.as_dict().items():
        if name in SKIP_PARAMS or name.startswith("bal_") or v == 0.0:
            continue
        spec = SPECS[name]
        for sign in (1, -1):
            want = v * (1 + sign * PARAM_SCALE)
            got = min(max(want, spec.lo), spec.hi)
            if got == v:
                continue
            label = f"{name} {sign * 20:+d} %" + ("" if got == want else f" (range: {got:g})")
            out.append(Condition("params +/-20 %", label, ("--set", f"{name}={got!r}")))
    return out


def walk_argv(robot: str, gait: str, seconds: float, condition: Condition, *,
              balance: bool, base_args: Sequence[str] = ()) -> list[str]:
    """The ``biped walk`` arguments of one run (``base_args``: e.g. ``--set`` items,
    before the condition's own, which win)."""
    argv = ["walk", "--json", "--stop-on-fall", "--robot", robot, "--gait", gait,
            "--seconds", f"{seconds:g}", *base_args, *condition.args]
    return argv if balance else [*argv, "--no-balance"]


class _Stderr:
    """A log stream that writes to whatever ``sys.stderr`` is at the time."""

    def write(self, text: str) -> int:
        return sys.stderr.write(text)

    def flush(self) -> None:
        sys.stderr.flush()


def worker_init() -> None:
    os.environ.setdefault("MUJOCO_GL", "egl")
    logging.basicConfig(level=logging.WARNING, stream=_Stderr(),  # type: ignore[arg-type]
                        format="%(levelname)s %(name)s: %(message)s")


def run_walk(argv: Sequence[str]) -> tuple[int, str, str]:
    """``biped <argv>`` in this process: (exit code, stdout, stderr)."""
    from robot.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(list(argv))
        except Exception as e:      # a bug in a run must not take the suite down
            print(f"{type(e).__name__}: {e}", file=sys.stderr)
            code = 1
    return code, out.getvalue(), err.getvalue()


def outcome(condition: Condition, balance: bool, code: int, stdout: str,
            stderr: str) -> Outcome:
    """The ``Outcome`` of one run from its exit code and output."""
    line = stdout.strip().splitlines()[-1] if stdout.strip() else ""
    try:
        r = json.loads(line)
    except json.JSONDecodeError:
        err = stderr.strip().splitlines()
        return Outcome(condition, balance, None,
                       error=err[-1] if err else f"exit {code}, no summary")
    return Outcome(condition, balance, bool(r.get("fell")), r.get("fell_at_s"),
                   float(r.get("distance_m", 0.0)), float(r.get("heading_change_deg", 0.0)),
                   summary=r)


def run_suite(robot: str, gait: str, conds: Iterable[Condition], *, seconds: float,
              balance_modes: Sequence[bool] = (True, False), jobs: int | None = None,
              progress: Callable[[Outcome], None] | None = None,
              base_args: Sequence[str] = ()) -> list[Outcome]:
    """Every condition in every balance mode, ``jobs`` at a time (default: the cores),
    in suite order."""
    work = [(c, b) for c in conds for b in balance_modes]
    jobs = jobs or os.cpu_count() or 1
    # Longest first, so that a long run does not start last and idle the other cores.
    order = sorted(range(len(work)), key=lambda i: -(work[i][0].seconds or seconds))
    done: dict[int, Outcome] = {}
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx,
                             initializer=worker_init) as pool:
        futures = {}
        for i in order:
            c, b = work[i]
            secs = seconds if c.seconds is None else c.seconds
            argv = walk_argv(robot, gait, secs, c, balance=b, base_args=base_args)
            futures[pool.submit(run_walk, argv)] = i
        try:
            for f in as_completed(futures):
                i = futures[f]
                c, b = work[i]
                try:
                    done[i] = outcome(c, b, *f.result())
                except Exception as e:   # the worker died (e.g. killed)
                    done[i] = Outcome(c, b, None, error=f"{type(e).__name__}: {e}")
                if progress is not None:
                    progress(done[i])
        except KeyboardInterrupt:        # the running walks stop on their own SIGINT
            pool.shutdown(wait=True, cancel_futures=True)
            raise
    return [done[i] for i in range(len(work))]


def survival_table(outcomes: Sequence[Outcome]) -> list[tuple[str, dict[bool, tuple[int, int]]]]:
    """Per group, in suite order: {balance: (survived, runs)} (failed runs count as falls)."""
    table: dict[str, dict[bool, tuple[int, int]]] = {}
    for o in outcomes:
        row = table.setdefault(o.condition.group, {})
        ok, n = row.get(o.balance, (0, 0))
        row[o.balance] = (ok + (o.fell is False), n + 1)
    return list(table.items())


def straightness(outcomes: Sequence[Outcome]) -> dict[bool, dict[str, Any]]:
    """Per balance mode, the flat STRAIGHT_S run's heading change [deg], lateral drift [m]
    and drift / distance, and whether both are inside the goal."""
    out: dict[bool, dict[str, Any]] = {}
    for o in outcomes:
        if o.condition.group != "flat 60 s" or o.fell is None:
            continue
        drift = float(o.summary.get("lateral_drift_m", 0.0))
        ratio = abs(drift) / o.distance_m if o.distance_m > 0 else math.inf
        out[o.balance] = {"heading_deg": o.heading_deg, "drift_m": drift,
                          "drift_ratio": ratio, "distance_m": o.distance_m, "fell": o.fell,
                          "ok": (not o.fell and abs(o.heading_deg) <= STRAIGHT_DEG
                                 and ratio <= STRAIGHT_DRIFT)}
    return out
