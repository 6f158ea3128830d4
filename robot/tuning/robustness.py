"""The robustness suite: simulated walks under perturbations, with and without balance.

Each condition (robot.tuning.conditions) is one walk built as `biped walk --json
--stop-on-fall` builds it (robot.run.walk: the same engine, IMU, balance and run, so the
suite measures the product, not a copy of it), run in this process through
``robot.run.run.execute``; ``run_suite`` spreads them over a pool of worker processes,
one per core, each running one walk after the other (no interpreter start and imports
per run). A condition survives when the walk does not fall (the simulated bus's watch:
torso low or tilted past the fall threshold) in ``seconds`` of gait, covers the
condition's ``reach_m`` where it has one (the stairs), and, where it must walk on (the
pushes), keeps WALK_ON_SHARE of the flat walk's speed in the same suite (``judge``).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import multiprocessing
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Any

from robot.bus.factory import make_bus
from robot.config.gait_file import load_gait
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_AT_S, PUSH_NS, PUSH_PHASES
from robot.errors import BipedError
from robot.run.run import execute
from robot.run.spec import RunOptions
from robot.run.switching import PresetSwitch
from robot.run.walk import walk_imu, walk_spec, walk_summary
from robot.tuning.conditions import (
    AFTER_PUSH_S,
    IMU_NOISE,
    PARAM_SCALE,
    SKIP_PARAMS,
    STRAIGHT_DEG,
    STRAIGHT_DRIFT,
    STRAIGHT_S,
    WALK_ON_SHARE,
    Condition,
    check_seconds,
    conditions,
    scaled_params,
)

__all__ = ["AFTER_PUSH_S", "IMU_NOISE", "PARAM_SCALE", "PUSH_AT_S", "PUSH_NS", "PUSH_PHASES",
           "SKIP_PARAMS", "STRAIGHT_DEG", "STRAIGHT_DRIFT", "STRAIGHT_S", "WALK_ON_SHARE",
           "Condition", "Outcome", "WalkJob", "check_seconds", "conditions", "judge",
           "run_condition", "run_suite", "scaled_params", "straightness", "survival_table",
           "worker_init"]


@dataclass
class Outcome:
    """The result of one condition with balance on or off. stood: it did not fall but
    did not walk on either (``judge``: under WALK_ON_SHARE of the flat walk's speed, or
    no flat walk to compare with), so it did not survive."""

    condition: Condition
    balance: bool
    fell: bool | None                      # None: the run failed (error set)
    fell_at_s: float | None = None
    distance_m: float = 0.0
    heading_deg: float = 0.0
    error: str = ""
    summary: dict[str, Any] = field(default_factory=dict)
    stood: bool = False

    @property
    def speed_m_s(self) -> float:
        """Forward speed over the run [m/s] (0 for a run that failed)."""
        return float(self.summary.get("speed_m_s", 0.0))

    @property
    def survived(self) -> bool:
        return self.fell is False and not self.stood


def judge(outcomes: Sequence[Outcome]) -> list[Outcome]:
    """``outcomes`` with ``stood`` set on each run that must walk on (``walk_on``), did
    not fall and went slower than WALK_ON_SHARE x the unpushed flat walk of its balance
    mode among ``outcomes`` (a flat walk that fell or is missing: no run walks on)."""
    flat = {o.balance: o.speed_m_s for o in outcomes
            if o.condition.group == "flat" and o.fell is False}
    return [dataclasses.replace(o, stood=o.speed_m_s < WALK_ON_SHARE * flat[o.balance]
                                if o.balance in flat else True)
            if o.condition.walk_on and o.fell is False else o for o in outcomes]


@dataclass(frozen=True)
class WalkJob:
    """One walk of the suite: robot (bundled name or path), the preset's name (for the
    summary) and its parameters (the condition's changes go on top), the gait seconds
    unless the condition has its own, the condition, balance on or off."""

    robot: str
    gait: str
    params: GaitParams
    seconds: float
    condition: Condition
    balance: bool = True


def worker_init() -> None:
    """A worker process: headless MuJoCo; only errors are logged (the walks' warnings,
    e.g. a target out of reach, would flood the terminal)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    logging.basicConfig(level=logging.ERROR, format="%(levelname)s %(name)s: %(message)s")


def run_condition(job: WalkJob) -> Outcome:
    """Walk ``job`` in this process (`biped walk --json --stop-on-fall` with the
    condition's options); a failed run is an Outcome with ``error`` set, never raised."""
    c = job.condition
    try:
        robot = load_robot(job.robot)
        params = (job.params.replace(dict(c.changes), where="--set") if c.changes
                  else job.params)
        bus = make_bus("sim", robot=robot, realtime=False, view=False, world=c.world)
        imu = walk_imu(robot, bus, balance=job.balance, noise=c.imu_noise)
        secs = job.seconds if c.seconds is None else c.seconds
        switches = tuple(PresetSwitch(t, name, load_gait(name).for_robot(robot))
                         for t, name in c.switches)
        spec = walk_spec(robot, params, bus, gait=job.gait, imu=imu,
                         options=RunOptions(seconds=secs, stop_on_fall=True),
                         switches=switches)
        r = walk_summary(spec, execute(spec), gait=job.gait)
    except BipedError as e:
        return Outcome(c, job.balance, None, error=str(e))
    except Exception as e:      # a bug in a run must not take the suite down
        logging.getLogger(__name__).exception("walk %s failed", c.name)
        return Outcome(c, job.balance, None, error=f"{type(e).__name__}: {e}")
    # A run a servo fault stopped early (e.g. the watchdog on an overloaded knee: the
    # servos go limp) did not survive either, though the torso had not yet fallen.
    stopped = r.get("stop_reason") not in ("completed", None)
    # A walk that must get somewhere (the stairs: past the last riser) and did not, failed.
    short = c.reach_m is not None and float(r.get("distance_m", 0.0)) < c.reach_m
    return Outcome(c, job.balance, bool(r.get("fell")) or stopped or short, r.get("fell_at_s"),
                   float(r.get("distance_m", 0.0)), float(r.get("heading_change_deg", 0.0)),
                   summary=r)


def run_suite(robot: str, gait: str, params: GaitParams, conds: Iterable[Condition], *,
              seconds: float, balance_modes: Sequence[bool] = (True, False),
              jobs: int | None = None,
              progress: Callable[[Outcome], None] | None = None) -> list[Outcome]:
    """Every condition in every balance mode for preset ``gait`` with ``params`` (its
    ``--set`` items applied), ``jobs`` at a time (default: the cores), in suite order."""
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
            job = WalkJob(robot, gait, params, seconds, c, balance=b)
            futures[pool.submit(run_condition, job)] = i
        try:
            for f in as_completed(futures):
                i = futures[f]
                c, b = work[i]
                try:
                    done[i] = f.result()
                except Exception as e:   # the worker died (e.g. killed)
                    done[i] = Outcome(c, b, None, error=f"{type(e).__name__}: {e}")
                if progress is not None:
                    progress(done[i])
        except KeyboardInterrupt:        # the running walks stop on their own SIGINT
            pool.shutdown(wait=True, cancel_futures=True)
            raise
    return judge([done[i] for i in range(len(work))])


def survival_table(outcomes: Sequence[Outcome]) -> list[tuple[str, dict[bool, tuple[int, int]]]]:
    """Per group, in suite order: {balance: (survived, runs)} (failed runs count as falls;
    ``outcomes`` as ``judge`` returns them)."""
    table: dict[str, dict[bool, tuple[int, int]]] = {}
    for o in outcomes:
        row = table.setdefault(o.condition.group, {})
        ok, n = row.get(o.balance, (0, 0))
        row[o.balance] = (ok + o.survived, n + 1)
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
