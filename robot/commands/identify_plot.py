"""The plot of ``biped identify check --plot``: per log, the goal, the recorded and the
simulated position over time, with the mean error in the panel's title."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from robot.previs.figure_file import save_figure
from robot.servo.pendulum_log import PendulumLog


def plot_replays(logs: Sequence[PendulumLog], simulated: npt.NDArray[np.float64], path: str, *,
                 title: str) -> None:
    """Write a PNG to ``path``: one panel per log (``simulated``: one row per log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = min(4, len(logs))
    rows = math.ceil(len(logs) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows), squeeze=False)
    for ax, log, sim in zip(axes.flat, logs, simulated, strict=False):
        n = len(log.t)
        error = float(np.abs(sim[:n] - log.position).mean())
        ax.plot(log.t, log.goal, "k--", lw=1, label="goal")
        ax.plot(log.t, log.position, "C0", lw=1.5, label="recorded")
        ax.plot(log.t, sim[:n], "C3", lw=1.2, label="simulated")
        off = ~log.torque_enable
        if off.any():
            ax.fill_between(log.t, 0, 1, where=off, color="0.85", transform=ax.get_xaxis_transform(),
                            label="torque off")
        ax.set_title(f"{log.name}\nkp {log.kp}, {log.trajectory}: {error:.3f} rad", fontsize=8)
        ax.set_xlabel("t [s]", fontsize=8)
        ax.set_ylabel("q [rad]", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[len(logs):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)
