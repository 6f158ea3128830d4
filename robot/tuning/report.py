"""What `biped tune` leaves behind: the preset (checked by the normal loader), a table of
the best parameters against the starting preset with the survival of both per condition
group, and the optimisation history and parameter importance as PNGs."""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import optuna

from robot.config.gait_file import Gait, gait_to_toml, load_gait
from robot.config.params import SPECS, GaitParams
from robot.errors import ConfigError
from robot.files.atomic import write_text
from robot.previs.figure_file import save_figure
from robot.tuning.objective import WALK_SHARE
from robot.tuning.space import Knob


def write_preset(path: str | Path, params: GaitParams, *, name: str,
                 description: str) -> Gait:
    """Write ``params`` as a gait preset and read it back with the normal loader; the
    file must give the same parameters exactly."""
    path = Path(path)
    gait = Gait(name=name, params=params, source=str(path))
    text = f"# {description}\n" + gait_to_toml(gait)
    write_text(path, text)
    back = load_gait(str(path))
    if back.params != params:
        raise ConfigError(f"{path}: the written preset does not load back unchanged")
    return back


def group_survival(runs_json: str, groups: dict[str, str]) -> dict[str, tuple[int, int]]:
    """{group: (survived, runs)} from a trial's per-condition JSON."""
    out: dict[str, tuple[int, int]] = {}
    for name, result in json.loads(runs_json).items():
        g = groups.get(name, name)
        ok, n = out.get(g, (0, 0))
        out[g] = (ok + (result == "ok"), n + 1)
    return out


class WalkFigures(NamedTuple):
    """The flat walk's speeds [m/s]: the target, the starting preset's and the tuned
    one's, and the slowest bumps run's of both (None: none, or it fell)."""

    target: float | None
    start: float | None
    best: float | None
    bumps_start: float | None = None
    bumps_best: float | None = None


def cadence(p: GaitParams) -> float:
    """Steps per minute (two per gait cycle)."""
    return 120.0 / p.cycle_s if math.isfinite(p.cycle_s) and p.cycle_s > 0 else 0.0


def _speed(v: float | None) -> str:
    return "fell" if v is None else f"{v:.3f}"


def format_report(knobs: Sequence[Knob], start: GaitParams, best: GaitParams,
                  start_score: float, best_score: float | None,
                  start_groups: dict[str, tuple[int, int]],
                  best_groups: dict[str, tuple[int, int]], *,
                  walk: WalkFigures | None = None) -> str:
    lines = [f"{'parameter':<18}{'start':>12}{'tuned':>12}  unit      range searched",
             "-" * 66]
    for k in knobs:
        t = k.targets[0]
        lines.append(f"{k.name:<18}{getattr(start, t):>12.4g}{getattr(best, t):>12.4g}  "
                     f"{SPECS[t].unit:<9} [{k.lo:.4g}, {k.hi:.4g}]")
    best_text = "-" if best_score is None else f"{best_score:.3f}"
    lines += ["", f"score (walks x (runs + 1) + survived + 0.9 x quality): start {start_score:.3f}, tuned "
              f"{best_text}", "", f"{'condition':<18}{'start':>10}{'tuned':>10}",
              "-" * 38]
    for g in dict.fromkeys([*start_groups, *best_groups]):
        s, b = start_groups.get(g, (0, 0)), best_groups.get(g, (0, 0))
        lines.append(f"{g:<18}{s[0]:>6}/{s[1]:<3}{b[0]:>6}/{b[1]:<3}")
    if walk is not None:
        target = ("none (no reference)" if walk.target is None else
                  f"{walk.target:.3f} m/s, walking from {WALK_SHARE * walk.target:.3f}")
        lines += [f"{'speed m/s (flat)':<18}{_speed(walk.start):>10}{_speed(walk.best):>10}"
                  f"  target {target}",
                  f"{'speed m/s (bumps)':<18}{_speed(walk.bumps_start):>10}"
                  f"{_speed(walk.bumps_best):>10}  the slowest run (walks from the same)",
                  f"{'cadence steps/min':<18}{cadence(start):>10.1f}{cadence(best):>10.1f}",
                  f"{'crouch (stance)':<18}{start.stance:>10.3f}{best.stance:>10.3f}"
                  "  hip height / leg length"]
    return "\n".join(lines)


#: Fewer finished trials than this: the importance plot says it is a rough guide.
FEW_TRIALS = 30


def plot_study(study: optuna.Study, prefix: str | Path, *,
               start_score: float | None = None) -> list[Path]:
    """history and importance PNGs at ``prefix``.history.png / .importance.png (the
    importance needs two finished trials; PED-ANOVA, which needs no scikit-learn). The
    history has whole trial numbers and a line at the starting preset's score; the
    importance of a handful of trials says how little it rests on."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import optuna.visualization.matplotlib as ovm
    from matplotlib.ticker import MaxNLocator

    out: list[Path] = []

    def save(ax: Any, suffix: str) -> None:
        ax.figure.set_size_inches(8, 4.5)
        ax.figure.tight_layout()
        path = Path(f"{prefix}.{suffix}.png")
        save_figure(ax.figure, path)
        plt.close(ax.figure)
        out.append(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ax: Any = ovm.plot_optimization_history(study)
        ax.set_ylabel("score (walks x (runs + 1) + survived + 0.9 x quality)")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        if start_score is not None:
            ax.axhline(start_score, color="tab:green", ls="--", lw=1.2,
                       label=f"starting preset ({start_score:.3f})")
            ax.legend(fontsize=8, loc="lower right")
        save(ax, "history")
        done = study.get_trials(deepcopy=False,
                                states=(optuna.trial.TrialState.COMPLETE,))
        if len(done) >= 2 and len({t.value for t in done}) > 1:
            imp: Any = ovm.plot_param_importances(
                study, evaluator=optuna.importance.PedAnovaImportanceEvaluator())
            if len(done) < FEW_TRIALS:
                imp.set_title(f"Hyperparameter Importances\nonly {len(done)} trials: a rough "
                              f"guide; below about {FEW_TRIALS} trials the ranking can change "
                              "with the next few", fontsize=9)
            save(imp, "importance")
    return out
