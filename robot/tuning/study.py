"""The Optuna study behind `biped tune`: storage, sampler, pruner and worker processes.

One study lives in an RDB storage (SQLite by default, one file; PostgreSQL or MySQL URLs
work the same way, so several machines can work on one study). Each worker process runs
trials one after the other against the shared storage until the study holds ``trials``
finished ones (complete or pruned): stopping and running the same command again resumes
it. Sampler: TPE (multivariate, with a constant liar so that parallel workers do not
propose the same point): it does well with the small budgets a robot owner can afford
(tens of trials) and works with pruning; CMA-ES needs many more trials per generation
before it moves and gains nothing from pruned trials. Pruner: median (a trial whose
running score after k conditions is below the median of earlier trials at k stops: most
of all, one that falls early).
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import optuna

from robot.config.params import GaitParams
from robot.errors import ConfigError
from robot.tuning.conditions import Condition
from robot.tuning.objective import (
    CANDIDATE,
    Evaluation,
    Setup,
    evaluate,
    rescore,
    summary_json,
)
from robot.tuning.robustness import WalkJob, run_condition
from robot.tuning.space import Knob, apply

log = logging.getLogger(__name__)

FINISHED = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)


@dataclass(frozen=True)
class Plan:
    """Everything a worker needs: the study's storage URL and name, the setup, the start
    parameters, the knobs, the finished trials wanted in all, and the sampler seed."""

    storage: str
    study: str
    setup: Setup
    start: GaitParams
    knobs: tuple[Knob, ...]
    trials: int
    seed: int = 0


def storage_of(url: str) -> optuna.storages.RDBStorage:
    """An RDB storage; SQLite waits up to a minute for a lock (several workers write)."""
    kwargs: dict[str, Any] = {}
    if url.startswith("sqlite"):
        kwargs["engine_kwargs"] = {"connect_args": {"timeout": 60}}
    try:
        return optuna.storages.RDBStorage(url, **kwargs)
    except Exception as e:   # a bad URL, a missing driver, a server that does not answer
        raise ConfigError(f"--storage {url}: {type(e).__name__}: {e}".splitlines()[0]) from e


def open_study(plan: Plan) -> optuna.Study:
    """Create or load the study (maximising the score)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        sampler = optuna.samplers.TPESampler(multivariate=True, constant_liar=True,
                                             seed=plan.seed,
                                             n_startup_trials=max(4, len(plan.knobs)))
    pruner = optuna.pruners.MedianPruner(n_startup_trials=4, n_warmup_steps=1)
    return optuna.create_study(storage=storage_of(plan.storage), study_name=plan.study,
                               direction="maximize", sampler=sampler, pruner=pruner,
                               load_if_exists=True)


def finished(study: optuna.Study) -> int:
    return len(study.get_trials(deepcopy=False, states=FINISHED))


def objective(plan: Plan) -> Callable[[optuna.Trial], float]:
    def run(trial: optuna.Trial) -> float:
        x = {k.name: trial.suggest_float(k.name, k.lo, k.hi) for k in plan.knobs}
        params = apply(plan.start, plan.knobs, x)

        def report(step: int, score: float) -> None:
            trial.report(score, step)
            if trial.should_prune():
                raise optuna.TrialPruned()
        ev = evaluate(plan.setup, params, report=report)
        trial.set_user_attr("worker_pid", os.getpid())
        trial.set_user_attr("runs", summary_json(ev))
        trial.set_user_attr("survived", ev.survived)
        trial.set_user_attr("terms", ev.terms)
        trial.set_user_attr("speed_m_s", trial_speed(ev))
        trial.set_user_attr("walking", ev.walking)
        trial.set_user_attr("tier", ev.tier)
        trial.set_user_attr("bumps_speed_m_s", ev.slowest("bumps"))
        return ev.score
    return run


def trial_speed(ev: Evaluation) -> float | None:
    """The flat walk's speed [m/s] (None: it fell or did not run)."""
    flat = ev.flat
    return None if not flat or flat.get("fell", True) else float(flat["speed_m_s"])


def work(plan: Plan, worker: int = 0, parent: int | None = None, *,
         progress: Callable[[int, float | None], None] | None = None) -> None:
    """One worker: trials until the study holds ``plan.trials`` finished ones, or until
    the process that started it (``parent``) is gone; ``progress(finished, best score)``
    after each of its trials (in this process: one job)."""
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    os.environ.setdefault("MUJOCO_GL", "egl")
    logging.getLogger("robot").setLevel(logging.ERROR)
    study = open_study(Plan(**{**plan.__dict__, "seed": plan.seed + 7919 * worker}))
    stop = optuna.study.MaxTrialsCallback(plan.trials, states=FINISHED)

    def orphaned(st: optuna.Study, _trial: optuna.trial.FrozenTrial) -> None:
        if parent is not None and os.getppid() != parent:
            st.stop()
    def report(st: optuna.Study, _trial: optuna.trial.FrozenTrial) -> None:
        if progress is not None:
            top = best_trial(st)
            progress(finished(st), top.value if top is not None else None)
    if finished(study) < plan.trials:
        study.optimize(objective(plan), callbacks=[stop, orphaned, report],
                       gc_after_trial=True)


def run_study(plan: Plan, *, jobs: int,
              progress: Callable[[int, float | None], None] | None = None) -> optuna.Study:
    """Run ``jobs`` worker processes (1: in this process) until the study is done;
    progress(finished trials, best score) after each trial (one job) or about once a
    second (several)."""
    study = open_study(plan)
    study.set_user_attr("knobs", [list(k) for k in plan.knobs])
    if jobs <= 1:
        work(plan, progress=progress)
        return study
    ctx = multiprocessing.get_context("spawn")
    procs = [ctx.Process(target=work, args=(plan, i, os.getpid()), daemon=False)
             for i in range(jobs)]
    for p in procs:
        p.start()
    try:
        while any(p.is_alive() for p in procs):
            if progress is not None:
                top = best_trial(study)
                progress(finished(study), top.value if top is not None else None)
            time.sleep(1.0)
    except KeyboardInterrupt:        # the workers get the same SIGINT and stop too
        for p in procs:
            p.join(timeout=30)
        raise
    for p in procs:
        p.join()
    bad = [p.exitcode for p in procs if p.exitcode]
    if bad:
        log.warning("%d tuning worker(s) ended with exit codes %s", len(bad), bad)
    return study


def best_params(study: optuna.Study, plan: Plan) -> GaitParams:
    """The start parameters with the best trial's knobs (the start if nothing finished)."""
    best = best_trial(study)
    return plan.start if best is None else apply(plan.start, plan.knobs, best.params)


def best_trial(study: optuna.Study) -> optuna.trial.FrozenTrial | None:
    done = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    return max(done, key=lambda t: t.value if t.value is not None else -math.inf,
               default=None)


def flat_speed(robot: str, params: GaitParams, seconds: float) -> float | None:
    """The speed [m/s] of ``params``' flat walk on ``robot`` (balance on), None if it
    fell: a fallen run's speed is no reference."""
    flat = run_condition(WalkJob(robot, CANDIDATE, params, seconds, Condition("flat", "flat"),
                                 balance=True)).summary
    return None if not flat or flat.get("fell", True) else float(flat["speed_m_s"])


def references(study: optuna.Study, setup: Setup, start: GaitParams,
               *, target_speed: float | None,
               made_for: tuple[str, GaitParams] | None = None) -> tuple[Setup, dict[str, Any]]:
    """The setup with its quality references and the starting preset's evaluation, both
    kept in the study: measured once (the starting preset through the suite), read back
    when the study is resumed, so every trial of a study is scored alike.

    The target speed: ``target_speed`` (--speed), else the starting preset's flat speed on
    the robot it was made for (``made_for``: robot and the preset's parameters there;
    None: the robot being tuned), never a fallen run's (then no target: a warning)."""
    kept = study.user_attrs.get("reference")
    if kept is None:
        ev = evaluate(setup, start)
        flat = ev.flat
        speed = target_speed
        if speed is None:
            speed = (flat_speed(*made_for, setup.seconds) if made_for is not None
                     else float(flat["speed_m_s"]) if flat and not flat.get("fell") else None)
            if speed is None:
                log.warning("no target speed: the starting preset fell on the flat on %s; "
                            "give --speed", made_for[0] if made_for else setup.robot)
        energy = flat.get("energy_per_m") if flat and not flat.get("fell") else None
        ref_setup = Setup(setup.robot, setup.suite, setup.seconds, speed, energy, setup.skip)
        kept = {"target_speed": speed, "baseline_energy": energy,
                "score": rescore(ev, ref_setup),
                "runs": summary_json(ev), "survived": ev.survived, "runs_total":
                len(ev.outcomes), "speed_m_s": trial_speed(ev),
                "bumps_speed_m_s": ev.slowest("bumps")}
        study.set_user_attr("reference", kept)
    ref = Setup(setup.robot, setup.suite, setup.seconds, kept["target_speed"],
                kept["baseline_energy"], setup.skip)
    return ref, kept


__all__: Sequence[str] = ("Evaluation", "Plan", "best_params", "best_trial", "open_study",
                          "references", "run_study", "storage_of")
