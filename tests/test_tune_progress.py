"""What `biped tune` shows a person: a line per finished trial when its output is not a
terminal; the history with whole trial numbers and the starting score as a line; the
importance plot's caveat for a handful of trials; n/N beside every robustness bar."""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib
import optuna
import pytest

from robot.commands.robustness import plot_survival
from robot.tuning.progress import TrialProgress
from robot.tuning.report import plot_study

matplotlib.use("Agg")


def test_a_line_per_trial_when_not_a_terminal() -> None:
    out = io.StringIO()
    progress = TrialProgress(5, stream=out)
    assert progress.bar is None
    progress(1, 0.5)
    progress(1, 0.5)          # nothing new: nothing printed
    progress(3, 0.75)         # two finished since: two lines, the best on the last
    progress.close()
    assert out.getvalue().splitlines() == ["trial 1/5 finished, best score 0.500",
                                           "trial 2/5 finished",
                                           "trial 3/5 finished, best score 0.750"]
    quiet = io.StringIO()
    TrialProgress(5, quiet=True, stream=quiet)(2, 0.1)
    assert quiet.getvalue() == ""


def _study(n: int) -> optuna.Study:
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction="maximize", sampler=optuna.samplers.RandomSampler(1))
    study.optimize(lambda t: -(t.suggest_float("a", 0, 1) - 0.3) ** 2
                   + 0.1 * t.suggest_float("b", 0, 1), n_trials=n)
    return study


def test_history_has_whole_trials_and_the_start_line(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib.pyplot as plt
    kept: list[object] = []
    monkeypatch.setattr(plt, "close", kept.append)          # look at the figures after
    pngs = plot_study(_study(6), tmp_path / "t", start_score=-0.05)
    assert [p.name for p in pngs] == ["t.history.png", "t.importance.png"]
    history, importance = (fig.axes[0] for fig in kept)     # type: ignore[attr-defined]
    history.figure.canvas.draw()
    ticks = [t for t in history.get_xticks() if history.get_xlim()[0] <= t
             <= history.get_xlim()[1]]
    assert ticks and all(float(t).is_integer() for t in ticks)
    start = [ln for ln in history.get_lines() if "starting preset" in ln.get_label()]
    assert start and set(start[0].get_ydata()) == {-0.05}
    assert "only 6 trials" in importance.get_title()


def test_survival_bars_say_n_of_n(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib.pyplot as plt
    kept: list[object] = []
    monkeypatch.setattr(plt, "close", kept.append)
    plot_survival([("slopes", {True: (0, 6), False: (0, 6)}), ("pushes", {True: (4, 8)})],
                  tmp_path / "suite.png", title="suite")
    texts = [t.get_text() for t in kept[0].axes[0].texts]   # type: ignore[attr-defined]
    assert texts.count("0/6") == 2 and "4/8" in texts
