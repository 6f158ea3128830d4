"""Curve files: the gait as CSV (t, paper channels, q_<joint>) and a plot a person can read."""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from robot.config.joint_names import limb_groups
from robot.files.atomic import write_text
from robot.gait.expressions import CHANNELS
from robot.previs.figure_file import save_figure

# Channels grouped by body part, as the paper groups its expressions.
CHANNEL_GROUPS: dict[str, tuple[str, ...]] = {
    "pelvis and spine (eq 1-7)": ("f_pelvis", "f_spine", "StY", "StZ", "CtZ", "CtY",
                                  "StY_ik", "StZ_ik"),
    "legs and feet (eq 8-15)": ("ty", "tz", "Ftau", "RightFoot_tY", "RightFoot_tZ",
                                "LeftFoot_tY", "LeftFoot_tZ", "RightToe_tY", "LeftToe_tY",
                                "RightUpLeg_tZ", "RightUpLeg_tY", "LeftUpLeg_tZ",
                                "LeftUpLeg_tY"),
    "shoulders and arms (eq 16-20)": ("Atau_R", "Atau_L", "RightArm_tY", "RightArm_tZ",
                                      "LeftArm_tY", "LeftArm_tZ", "RightShoulder_tY",
                                      "RightShoulder_tZ", "LeftShoulder_tY",
                                      "LeftShoulder_tZ"),
}
assert sorted(n for g in CHANNEL_GROUPS.values() for n in g) == sorted(CHANNELS)


def write_csv(path: str | Path, times: npt.NDArray[np.float64],
              channels: dict[str, npt.NDArray[np.float64]], joint_names: tuple[str, ...],
              q: npt.NDArray[np.float64], *,
              extra: Mapping[str, npt.NDArray[np.float64]] | None = None) -> None:
    """Columns: ``t`` [s], every channel of equations.md, ``q_<joint>`` [rad], then the
    ``extra`` columns by name (ValueError if one is named as a column before it)."""
    more = dict(extra or {})
    header = ["t", *CHANNELS, *(f"q_{n}" for n in joint_names)]
    taken = set(header) & set(more)
    if taken:
        raise ValueError(f"column {sorted(taken)[0]!r} twice")
    data = np.column_stack([times, *(channels[c] for c in CHANNELS), *q, *more.values()])
    text = io.StringIO()
    w = csv.writer(text)
    w.writerow([*header, *more])
    w.writerows(data.tolist())  # repr precision: the channels round-trip exactly
    write_text(path, text.getvalue())


def palette(n: int) -> list[tuple[float, float, float, float]]:
    """``n`` distinct colours (n <= 20): tab20's dark shades first, then its light ones,
    so a panel of up to 10 lines gets 10 different hues."""
    import matplotlib

    if n > 20:
        raise ValueError(f"at most 20 distinct colours, asked for {n}")
    cmap = matplotlib.colormaps["tab20"]
    order = list(range(0, 20, 2)) + list(range(1, 20, 2))
    return [cmap(i) for i in order[:n]]


def outside_legend(ax: Any, *, n: int) -> None:
    """A legend right of the axes (never over the data)."""
    ax.legend(fontsize=7, ncol=1 if n <= 10 else 2, loc="upper left",
              bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)


def curves_figure(times: npt.NDArray[np.float64],
                  channels: dict[str, npt.NDArray[np.float64]], joint_names: tuple[str, ...],
                  q: npt.NDArray[np.float64], *, title: str) -> Any:
    """The curves figure: one panel per channel group, then leg and arm joint angles; a
    colour per line that does not repeat within a panel, legends outside the data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    limbs = limb_groups(joint_names)
    panels = len(CHANNEL_GROUPS) + len(limbs)
    fig, axes = plt.subplots(panels, 1, figsize=(14, 3.2 * panels), sharex=True,
                             layout="constrained")
    for ax, (group, names) in zip(axes, CHANNEL_GROUPS.items(), strict=False):
        for k, (n, colour) in enumerate(zip(names, palette(len(names)), strict=True)):
            # A channel equal to an earlier one (Atau_L = Atau_R at a straight walk) is
            # drawn dashed over it and says so, instead of vanishing under it.
            same = next((m for m in names[:k] if np.allclose(channels[m], channels[n])), None)
            ax.plot(times, channels[n], "--" if same else "-", lw=2.0 if same else 1.2,
                    color=colour, label=f"{n} (= {same})" if same else n)
        ax.set_title(group, loc="left", fontsize=10)
        ax.set_ylabel("channel [rig units]")
        outside_legend(ax, n=len(names))
    rest = axes[len(CHANNEL_GROUPS):]
    for ax, (label, members) in zip(rest, limbs, strict=True):
        idx = [joint_names.index(n) for n in members]
        for i, colour in zip(idx, palette(len(idx)), strict=True):
            ls = "-" if joint_names[i].startswith("r_") else "--"
            ax.plot(times, q[i], ls, label=joint_names[i], lw=1.2, color=colour)
        ax.set_title(label, loc="left", fontsize=10)
        ax.set_ylabel("angle [rad]")
        outside_legend(ax, n=len(idx))
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.set_xlabel("t [s]")
        ax.tick_params(labelbottom=True)
    fig.suptitle(f"{title}\nrig units: the paper's Maya rig's lengths and angles, as its "
                 "equations give them; the robot scales lengths by its leg length "
                 "(docs/gait.md)", fontsize=10)
    return fig


def plot_curves(path: str | Path, times: npt.NDArray[np.float64],
                channels: dict[str, npt.NDArray[np.float64]], joint_names: tuple[str, ...],
                q: npt.NDArray[np.float64], *, title: str) -> None:
    """The curves figure (``curves_figure``) as a PNG."""
    import matplotlib.pyplot as plt

    fig = curves_figure(times, channels, joint_names, q, title=title)
    save_figure(fig, path)
    plt.close(fig)
