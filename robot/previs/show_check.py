"""The physics check of a show: from what the simulation recorded while the show played
(sim/mujoco/show_watch.py), whether and when the robot fell, its support margin over time,
and each servo's torque and temperature headroom, as a table and a plot.

Torque headroom: 100 % minus the peak |torque| as a share of the servo's stall torque
(robot/servo/models.py, datasheet); temperature headroom: the watchdog's limit
(robot/loop/watchdog.py ``max_temperature_c``, where a run on the bus would stop) minus
the peak temperature the bus reported. A joint with under ``TIGHT_PCT`` % of torque left,
or a fall, or the centre of mass outside the support polygon, is flagged.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from robot.config.joint_names import limb_groups
from robot.config.robot import RobotConfig
from robot.loop.watchdog import WatchdogConfig
from robot.previs.curves import outside_legend, palette
from robot.previs.figure_file import save_figure

Array = npt.NDArray[np.float64]
#: Torque headroom below this [%] is flagged.
TIGHT_PCT = 20.0


@dataclass(frozen=True)
class JointHeadroom:
    """peak_nm [N m] at t_peak [s]; peak_pct, mean_pct: of stall torque [%]; headroom_pct
    [%]; peak_c [°C] (NaN: not reported); temp_headroom_k [K]."""

    joint: str
    peak_nm: float
    t_peak: float
    peak_pct: float
    mean_pct: float
    headroom_pct: float
    peak_c: float
    temp_headroom_k: float


@dataclass(frozen=True)
class ShowCheck:
    """t (n,) [s] of show time (0: the show's first tick after the ramp in); margin (n,)
    [m]; torque_pct (n, joints) [% of stall]; fell_at [s of show time] or None."""

    robot: str
    t: Array
    margin: Array
    torque_pct: Array
    joints: tuple[JointHeadroom, ...]
    fell_at: float | None

    @property
    def min_margin(self) -> tuple[float, float]:
        """Smallest support margin [m] and its time [s] (NaN if no foot was ever down)."""
        ok = np.isfinite(self.margin)
        if not ok.any():
            return math.nan, math.nan
        k = int(np.nanargmin(self.margin))
        return float(self.margin[k]), float(self.t[k])

    @property
    def outside_s(self) -> float:
        """Time [s] with the centre of mass outside the support polygon or no foot down."""
        dt = float(np.median(np.diff(self.t))) if len(self.t) > 1 else 0.0
        return dt * int(np.sum(~(self.margin >= 0)))

    def as_dict(self) -> dict[str, Any]:
        m, tm = self.min_margin
        return {"fell": self.fell_at is not None, "fell_at_s": self.fell_at,
                "min_support_margin_m": None if math.isnan(m) else m,
                "min_support_margin_at_s": None if math.isnan(tm) else tm,
                "outside_support_s": self.outside_s,
                "joints": [{k: (None if isinstance(v, float) and math.isnan(v) else v)
                            for k, v in j.__dict__.items()} for j in self.joints]}

    def table(self) -> str:
        m, tm = self.min_margin
        fell = (f"FELL at t={self.fell_at:.2f} s" if self.fell_at is not None
                else "stayed up")
        lines = [f"physics check on {self.robot} (sim): {fell}; support margin min "
                 f"{m * 1000:+.1f} mm at t={tm:.2f} s, {self.outside_s:.2f} s outside the "
                 "support polygon",
                 f"{'joint':<18}{'peak N m':>9}{'at s':>7}{'peak %':>8}{'mean %':>8}"
                 f"{'headroom %':>12}{'peak °C':>9}{'left K':>8}", "-" * 79]
        for j in self.joints:
            flag = "  <- tight" if j.headroom_pct < TIGHT_PCT else ""
            lines.append(f"{j.joint:<18}{j.peak_nm:>9.3f}{j.t_peak:>7.2f}{j.peak_pct:>8.1f}"
                         f"{j.mean_pct:>8.1f}{j.headroom_pct:>12.1f}{j.peak_c:>9.1f}"
                         f"{j.temp_headroom_k:>8.1f}{flag}")
        return "\n".join(lines)


def build_check(robot: RobotConfig, t: Sequence[float], margin: Sequence[float],
                torque_nm: Sequence[Array], temperature: Sequence[Sequence[float]], *,
                start: float, fell_at: float | None) -> ShowCheck:
    """From the watch's lists: loop time ``t`` [s] (``start``: the show's first tick),
    margin [m], |torque| per joint [N m] by tick, temperatures [°C] by read."""
    tt = np.asarray(t, dtype=float) - start
    tau = np.asarray(torque_nm, dtype=float).reshape(len(tt), len(robot.joints))
    stall = np.array([robot.servo(j).stall_torque for j in robot.joints])
    pct = 100.0 * tau / stall
    temps = np.asarray(temperature, dtype=float).reshape(-1, len(robot.joints))
    limit = WatchdogConfig().max_temperature_c
    rows = []
    for i, j in enumerate(robot.joints):
        k = int(np.argmax(pct[:, i])) if len(tt) else 0
        hot = float(np.nanmax(temps[:, i])) if np.isfinite(temps[:, i]).any() else math.nan
        rows.append(JointHeadroom(j.name, float(tau[k, i]) if len(tt) else 0.0,
                                  float(tt[k]) if len(tt) else 0.0,
                                  float(pct[k, i]) if len(tt) else 0.0,
                                  float(pct[:, i].mean()) if len(tt) else 0.0,
                                  100.0 - (float(pct[k, i]) if len(tt) else 0.0),
                                  hot, limit - hot))
    return ShowCheck(robot.name, tt, np.asarray(margin, dtype=float), pct, tuple(rows),
                     None if fell_at is None else fell_at - start)


def plot_check(check: ShowCheck, out: str | Path, *, title: str) -> None:
    """Support margin; torque as a share of stall by limb (legs, arms, extra joints); the
    headroom per joint as bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [j.joint for j in check.joints]
    groups = limb_groups(names)
    fig, axes = plt.subplots(2 + len(groups), 1, figsize=(13, 2.8 * (2 + len(groups))),
                             layout="constrained")
    ax = axes[0]
    ax.plot(check.t, 1000 * check.margin, lw=1.0, color="tab:blue", label="support margin")
    ax.axhline(0.0, color="black", lw=0.8, label="edge of the support polygon")
    if check.fell_at is not None:
        ax.axvline(check.fell_at, color="tab:red", lw=1.5, label=f"fell ({check.fell_at:.2f} s)")
    ax.set_title("centre of mass inside the support polygon (> 0) or outside (< 0); gaps: "
                 "no foot down", loc="left", fontsize=10)
    ax.set_ylabel("margin [mm]")
    outside_legend(ax, n=3)
    for ax, (label, group) in zip(axes[1:], groups, strict=False):
        for n, col in zip(group, palette(len(group)), strict=True):
            ax.plot(check.t, check.torque_pct[:, names.index(n)], lw=0.9, color=col, label=n)
        ax.axhline(100.0 - TIGHT_PCT, color="tab:red", lw=0.8, ls="--",
                   label=f"{100 - TIGHT_PCT:.0f} % of stall")
        ax.set_title(f"{label}: |torque| as a share of the servo's stall torque", loc="left",
                     fontsize=10)
        ax.set_ylabel("torque [% of stall]")
        outside_legend(ax, n=len(group) + 1)
    for ax in axes[:-1]:
        ax.set_xlabel("show time [s]")
        ax.grid(alpha=0.3)
    bars = axes[-1]
    head = [j.headroom_pct for j in check.joints]
    bars.bar(range(len(names)), head, color=["tab:red" if h < TIGHT_PCT else "tab:green"
                                             for h in head])
    bars.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=8)
    bars.set_ylabel("torque headroom [%]")
    bars.set_xlabel("joint")
    bars.set_title("torque headroom at the peak (100 % minus peak |torque| / stall)",
                   loc="left", fontsize=10)
    bars.grid(alpha=0.3, axis="y")
    fig.suptitle(title)
    save_figure(fig, out)
    plt.close(fig)
