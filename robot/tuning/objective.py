"""How good a parameter set is for `biped tune`: survive the perturbation set first, then
walk at the requested speed, straight, with low knee load and little energy.

``evaluate`` walks every condition of the robustness suite (robot.tuning.robustness: `--quick`
or the full one) in this process, one after the other, through the same run as the
`biped walk --stop-on-fall` a user runs (robot.tuning.robustness.run_condition: in
process, a typed result, no files), with balance on, and scores

    score = walks x (conditions + 1) + survived + 0.9 * quality,
    quality in [0, 1] from the flat walk:
    quality = 0.4 speed + 0.3 straightness + 0.15 (1 - knee load) + 0.15 energy

where walks counts the walking groups (SPEED_GROUPS: the flat, then the bumps) whose every
run stayed up and kept at least ``WALK_SHARE`` of the target speed, the bumps only once the
flat walks: a trial that creeps (or stands) on the flat cannot beat one that walks, and one
that walks the flat but creeps over bumps cannot beat one that walks both, whatever they
survive; within a tier one more survived condition always outranks any gain in quality.
The terms: speed 1 - |v - v_target| / v_target, the mean over the runs of SPEED_GROUPS
(a fallen one 0); straightness 1 - |heading| / 20 deg - |drift| / (0.2 distance); knee
load its mean share of stall torque; energy 1 - (J/m) / (2 x the starting preset's J/m).
A callback sees the running score after every condition (Optuna
prunes with it).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from robot.config.params import GaitParams
from robot.errors import ConfigError
from robot.tuning.robustness import (
    Condition,
    Outcome,
    WalkJob,
    conditions,
    judge,
    run_condition,
)

QUALITY_WEIGHT = 0.9
#: A flat walk slower than this share of the target speed does not count as walking.
WALK_SHARE = 0.8
#: The groups whose runs must keep that speed, in the order they count: a walk has to
#: cross small bumps at speed too (issue 22: a tuned preset walked the flat at 0.114 m/s
#: and 3 mm bumps at 0.039).
SPEED_GROUPS = ("flat", "bumps")


@dataclass(frozen=True)
class Setup:
    """robot: bundled name or path; suite: "quick" or "full"; seconds: per run [s];
    target_speed [m/s] and baseline_energy [J/m]: the references of the quality terms
    (None: no such term yet, e.g. while measuring the starting preset); skip: condition
    groups left out (e.g. "push left"; a group name ending in "*" is a prefix)."""

    robot: str
    suite: str = "quick"
    seconds: float = 12.0
    target_speed: float | None = None
    baseline_energy: float | None = None
    skip: tuple[str, ...] = ()

    def _replace(self, **changes: Any) -> Setup:
        return dataclasses.replace(self, **changes)


@dataclass
class Evaluation:
    """The outcome of every condition, the quality terms and the score."""

    outcomes: list[Outcome] = field(default_factory=list)
    terms: dict[str, float] = field(default_factory=dict)
    score: float = 0.0
    walking: bool = False
    tier: int = 0

    @property
    def survived(self) -> int:
        return sum(o.survived for o in judge(self.outcomes))

    @property
    def flat(self) -> dict[str, Any]:
        return next((o.summary for o in self.outcomes if o.condition.group == "flat"), {})

    def slowest(self, group: str) -> float | None:
        """The lowest forward speed [m/s] of ``group``'s runs (None: one fell, or none
        ran)."""
        runs = [o.summary for o in self.outcomes if o.condition.group == group]
        if not runs or any(r.get("fell", True) for r in runs):
            return None
        return min(float(r["speed_m_s"]) for r in runs)


def suite_for(setup: Setup, params: GaitParams) -> list[Condition]:
    """The conditions, flat first (its walk measures the quality); push times follow the
    parameters' own step."""
    conds = [c for c in conditions(params, quick=setup.suite == "quick")
             if not any(skipped(c.group, s) for s in setup.skip)]
    return sorted(conds, key=lambda c: c.group != "flat")


def skipped(group: str, pattern: str) -> bool:
    return group.startswith(pattern[:-1]) if pattern.endswith("*") else group == pattern


def check_skip(patterns: tuple[str, ...], params: GaitParams, suite: str) -> None:
    """Every --skip pattern must name a group of the suite (ConfigError listing them)."""
    groups = sorted({c.group for c in conditions(params, quick=suite == "quick")})
    for s in patterns:
        if s == "flat" or not any(skipped(g, s) for g in groups):
            valid = ", ".join(g for g in groups if g != "flat")
            raise ConfigError(f"--skip {s!r}: not a group of the {suite} suite (flat is "
                              f"always run); valid: {valid} (or a prefix ending in *)")


def quality(flat: dict[str, Any], setup: Setup) -> dict[str, float]:
    """The quality terms of the flat walk's summary (all 0 if it fell or did not run)."""
    if not flat or flat.get("fell", True):
        return {"speed": 0.0, "straight": 0.0, "knee": 0.0, "energy": 0.0}
    dist = float(flat["distance_m"])
    v = float(flat["speed_m_s"])
    target = setup.target_speed
    speed = 1.0 if target is None else max(0.0, 1.0 - abs(v - target) / max(target, 1e-3))
    drift = abs(float(flat["lateral_drift_m"])) / max(dist, 0.1)
    straight = max(0.0, 1.0 - abs(float(flat["heading_change_deg"])) / 20.0 - drift / 0.2)
    knee = max(0.0, 1.0 - float(flat.get("knee_load_pct", 100.0)) / 100.0)
    per_m = flat.get("energy_per_m")
    base = setup.baseline_energy
    energy = (1.0 if base is None else 0.0 if per_m is None
              else max(0.0, 1.0 - float(per_m) / (2.0 * base)))
    return {"speed": speed, "straight": straight, "knee": knee, "energy": energy}


def walks(flat: dict[str, Any], setup: Setup) -> bool:
    """The flat walk stayed up and kept ``WALK_SHARE`` of the target speed (any speed when
    there is no target)."""
    if not flat or flat.get("fell", True):
        return False
    target = setup.target_speed
    return target is None or float(flat["speed_m_s"]) >= WALK_SHARE * target


def walking_tier(outcomes: list[Outcome], setup: Setup) -> int:
    """How many of SPEED_GROUPS, in order, walk: the group ran and each of its runs
    ``walks`` (a group not run, e.g. skipped, ends the count)."""
    tier = 0
    for group in SPEED_GROUPS:
        runs = [o.summary for o in outcomes if o.condition.group == group]
        if not runs or not all(walks(r, setup) for r in runs):
            break
        tier += 1
    return tier


def speed_term(outcomes: list[Outcome], setup: Setup) -> float:
    """The quality's speed term: its mean over the runs of SPEED_GROUPS (a fallen one 0)."""
    terms = [quality(o.summary, setup)["speed"] for o in outcomes
             if o.condition.group in SPEED_GROUPS]
    return sum(terms) / len(terms) if terms else 0.0


def score(survived: int, terms: dict[str, float], *, tier: int, runs: int) -> float:
    """The score of the module docstring for ``runs`` conditions in all, ``tier`` walking
    groups."""
    return tier * float(runs + 1) + survived + (QUALITY_WEIGHT * combined(terms)
                                                if terms else 0.0)


def combined(terms: dict[str, float]) -> float:
    return (0.4 * terms["speed"] + 0.3 * terms["straight"] + 0.15 * terms["knee"]
            + 0.15 * terms["energy"])


def rescore(ev: Evaluation, setup: Setup) -> float:
    """``ev``'s score against ``setup``'s references (those it was walked with may have
    been None: the starting preset measuring them)."""
    terms = {**quality(ev.flat, setup), "speed": speed_term(ev.outcomes, setup)}
    return score(ev.survived, terms, tier=walking_tier(ev.outcomes, setup),
                 runs=len(ev.outcomes))


#: The preset name of a candidate's walks (their summaries' "gait").
CANDIDATE = "candidate"


def evaluate(setup: Setup, params: GaitParams, *,
             report: Callable[[int, float], None] | None = None) -> Evaluation:
    """Walk ``params`` through the suite. report(step, running score) after each
    condition may raise to stop early (a pruned trial)."""
    ev = Evaluation()
    suite = suite_for(setup, params)
    for step, c in enumerate(suite):
        ev.outcomes.append(run_condition(WalkJob(setup.robot, CANDIDATE, params,
                                                 setup.seconds, c, balance=True)))
        if c.group == "flat":
            ev.terms = quality(ev.outcomes[-1].summary, setup)
            ev.walking = walks(ev.outcomes[-1].summary, setup)
        if c.group in SPEED_GROUPS and ev.terms:
            ev.terms["speed"] = speed_term(ev.outcomes, setup)
        ev.tier = walking_tier(ev.outcomes, setup)
        ev.score = score(ev.survived, ev.terms, tier=ev.tier, runs=len(suite))
        if report is not None:
            report(step, ev.score)
    return ev


def summary_json(ev: Evaluation) -> str:
    """The per-condition results as JSON (kept with each trial; "stood": up, but it did
    not walk on, robot.tuning.robustness.judge)."""
    return json.dumps({o.condition.name: ("error: " + o.error) if o.fell is None
                       else "fell %.2f" % (o.fell_at_s or 0.0) if o.fell
                       else f"stood {o.speed_m_s:.3f} m/s" if o.stood else "ok"
                       for o in judge(ev.outcomes)})
