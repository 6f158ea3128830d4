"""Fitting a servo model to pendulum logs: Optuna's CMA-ES sampler searches the motor,
gearbox and firmware-scale parameters (``robot.servo.physics.FITTED``) and the rig's
mounting offset, minimising the mean closed-loop replay error over the training logs
(``sim.mujoco.pendulum``). Positive parameters are searched on a log scale within
physical bounds; the start point is the model the fit begins from.
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import optuna

from robot.servo.models import ServoModel
from robot.servo.pendulum_log import PendulumLog
from robot.servo.physics import ServoPhysics
from sim.mujoco.pendulum import PendulumBench

log = logging.getLogger(__name__)

#: Search bounds per parameter (low, high) [SI units]; all but the offset on a log scale.
BOUNDS: dict[str, tuple[float, float]] = {
    "gain_scale": (0.1, 5.0), "kt": (0.02, 5.0), "resistance": (0.2, 60.0),
    "armature": (1e-6, 0.1), "coulomb": (1e-5, 1.0), "viscous": (1e-6, 1.0),
    "stribeck": (1e-5, 1.0), "stribeck_speed": (0.01, 5.0), "max_velocity": (0.5, 40.0),
    "kd_scale": (0.01, 100.0), "load_friction": (1e-4, 1.0),
}
OFFSET_BOUND = 0.15  # rig mounting error searched within +- this [rad]
#: What a fit searches unless told otherwise (Coulomb-viscous, Stribeck and load terms).
DEFAULT_PARAMS = ("gain_scale", "kt", "resistance", "armature", "coulomb", "viscous",
                  "stribeck", "stribeck_speed", "load_friction")


@dataclass(frozen=True)
class FitResult:
    """physics: the fitted model; offset: the rig's mounting offset [rad];
    train_error: mean replay error on the training logs [rad] (never above the start's:
    the start is replayed too); trials: how many replays ran, the start's included."""

    physics: ServoPhysics
    offset: float
    train_error: float
    trials: int


def _clip(name: str, value: float) -> float:
    lo, hi = BOUNDS[name]
    return min(max(value, lo), hi)


def fit_physics(logs: Sequence[PendulumLog], servo: ServoModel, start: ServoPhysics, *,
                params: Sequence[str] = DEFAULT_PARAMS, trials: int = 800, seed: int = 0,
                offset: float = 0.0, fit_offset: bool = False, keep_stall: bool = False,
                source: str = "fitted",
                progress: Callable[[int, float], None] | None = None) -> FitResult:
    """Fit ``params`` of ``start`` to ``logs`` with the rig at ``offset`` [rad] (or the
    offset fitted too, with ``fit_offset``): about ``trials``
    CMA-ES evaluations from ``seed``, a generation at a time (every candidate of a
    generation replays in one MuJoCo model). Each fitted value is sourced as ``source``.
    ``keep_stall``: the resistance follows kt so that the stall torque stays the start's
    (for logs that never saturate the servo, which cannot tell it)."""
    unknown = sorted(set(params) - set(BOUNDS))
    if unknown:
        raise ValueError(f"cannot fit {unknown[0]}; valid: {', '.join(BOUNDS)}")
    if keep_stall:
        params = [p for p in params if p != "resistance"]
    dims = len(params) + fit_offset
    popsize = 4 + int(3 * math.log(dims))
    bench = PendulumBench(logs, servo, copies=popsize)
    x0 = {name: math.log(_clip(name, float(getattr(start, name)))) for name in params}
    if fit_offset:
        x0["offset"] = 0.0

    stall = start.kt / start.resistance   # [N m / (V duty)]

    def physics_of(x: Mapping[str, float]) -> ServoPhysics:
        values = {k: math.exp(x[k]) for k in params}
        if keep_stall:
            values["resistance"] = values.get("kt", start.kt) / stall
        return start.with_values(values, source=source)

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    with warnings.catch_warnings():   # x0 / sigma0: deprecated in 4.9, kept until 6.0
        warnings.simplefilter("ignore", FutureWarning)
        sampler = optuna.samplers.CmaEsSampler(x0=x0, sigma0=0.5, seed=seed, popsize=popsize,
                                               n_startup_trials=0,
                                               warn_independent_sampling=False)
    study = optuna.create_study(direction="minimize", sampler=sampler)
    for generation in range(max(1, math.ceil(trials / popsize))):
        asked = [study.ask() for _ in range(popsize)]
        xs = [{k: t.suggest_float(k, math.log(BOUNDS[k][0]), math.log(BOUNDS[k][1]))
               for k in params} for t in asked]
        offsets = [t.suggest_float("offset", -OFFSET_BOUND, OFFSET_BOUND) if fit_offset
                   else offset for t in asked]
        errors = bench.errors(bench.replay([physics_of(x) for x in xs], offset=offsets))
        for t, err in zip(asked, errors.mean(axis=1), strict=True):
            study.tell(t, float(err) if math.isfinite(err) else 10.0)
        if progress is not None:
            progress(generation, float(study.best_value))
    best = study.best_params
    # CMA-ES samples around the start but never replays the start itself: a short search
    # can end worse than where it began, and then the start is the result.
    started, start_offset = physics_of(x0), x0.get("offset", offset)
    start_error = float(bench.errors(bench.replay(started, offset=start_offset))[0].mean())
    if start_error <= study.best_value:
        return FitResult(physics=started, offset=start_offset, train_error=start_error,
                         trials=len(study.trials) + 1)
    return FitResult(physics=physics_of(best), offset=float(best.get("offset", offset)),
                     train_error=float(study.best_value), trials=len(study.trials) + 1)


def replay_errors(logs: Sequence[PendulumLog], servo: ServoModel, physics: ServoPhysics, *,
                  offset: float = 0.0) -> np.ndarray:
    """Mean |q_sim - q_log| per log [rad] (closed loop from each log's first state)."""
    bench = PendulumBench(logs, servo)
    return bench.errors(bench.replay(physics, offset=offset))[0]
