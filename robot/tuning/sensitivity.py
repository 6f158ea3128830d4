"""Which parameters matter: the score (robot.tuning.objective) of the starting preset
with one knob moved at a time, +-20 % of its value (a balance gain at 0 is switched on at
25 % and 50 % of its documented range instead), through the same suite as the tuner.
The knobs that move the score most are the ones worth searching (docs/tuning.md)."""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import NamedTuple

from robot.config.params import BALANCE, SPECS, GaitParams
from robot.tuning.objective import Setup, evaluate, rescore
from robot.tuning.robustness import worker_init
from robot.tuning.space import FIXED, PAIRS, Knob, apply, targets_of

STEP = 0.2


class Sensitivity(NamedTuple):
    """A knob, the values tried and the score of each, and the largest change from the
    start's score."""

    knob: str
    values: tuple[float, ...]
    scores: tuple[float, ...]
    change: float


def candidates(params: GaitParams) -> list[tuple[str, tuple[float, ...]]]:
    """Every searchable knob with the values to try."""
    paired = {t for pair in PAIRS.values() for t in pair}
    names = [*PAIRS, *(n for n in SPECS if n not in paired)]
    out = []
    for name in names:
        if name in FIXED:
            continue
        first = targets_of(name, "sensitivity")[0]
        spec, v = SPECS[first], getattr(params, first)
        if v != 0.0:
            values = tuple(min(max(v * (1 + s), spec.lo), spec.hi) for s in (-STEP, STEP))
        elif spec.group == BALANCE:
            values = tuple(spec.lo + f * (spec.hi - spec.lo) for f in (0.25, 0.5))
        else:
            continue
        out.append((name, tuple(x for x in values if x != v)))
    return out


def _score(job: tuple[Setup, GaitParams]) -> float:
    return evaluate(*job).score


def with_references(setup: Setup, params: GaitParams) -> tuple[Setup, float]:
    """The setup with the start's flat walk as the speed (unless given) and energy
    references, and the start's score against them."""
    ev = evaluate(setup, params)
    flat = ev.flat
    if not flat or flat.get("fell"):
        return setup, ev.score
    ref = setup._replace(
        target_speed=setup.target_speed if setup.target_speed is not None
        else float(flat["speed_m_s"]), baseline_energy=flat.get("energy_per_m"))
    return ref, rescore(ev, ref)


def study(setup: Setup, params: GaitParams, *, jobs: int,
          progress: Callable[[int, int], None] | None = None) -> tuple[float, list[Sensitivity]]:
    """The start's score and every candidate's sensitivity, largest change first."""
    cands = candidates(params)
    setup, base = with_references(setup, params)
    work: list[tuple[Setup, GaitParams]] = []
    for name, values in cands:
        knob = Knob(name, min(values), max(values), targets_of(name, "sensitivity"))
        work += [(setup, apply(params, [knob], {name: x})) for x in values]
    scores: list[float] = []
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=worker_init) as pool:
        for s in pool.map(_score, work):
            scores.append(s)
            if progress is not None:
                progress(len(scores), len(work))
    rest = scores
    out: list[Sensitivity] = []
    i = 0
    for name, values in cands:
        got = tuple(rest[i:i + len(values)])
        i += len(values)
        out.append(Sensitivity(name, values, got, max((abs(g - base) for g in got),
                                                      default=0.0)))
    return base, sorted(out, key=lambda s: -s.change)


def format_sensitivity(base: float, rows: Sequence[Sensitivity]) -> str:
    lines = [f"start score {base:.3f}", "",
             f"{'knob':<18}{'change':>8}  values tried -> scores", "-" * 60]
    for r in rows:
        tried = ", ".join(f"{v:.4g} -> {s:.2f}" for v, s in zip(r.values, r.scores,
                                                                  strict=True))
        lines.append(f"{r.knob:<18}{r.change:>8.3f}  {tried}")
    return "\n".join(lines)
