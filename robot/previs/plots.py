"""Plots of run records (`biped walk --record`, .csv or .jsonl) and curve files
(`biped curves`), told apart by their columns."""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from robot.config.joint_names import limb_groups
from robot.config.toml_io import parse_json
from robot.errors import ConfigError
from robot.gait.expressions import CHANNELS
from robot.previs.curves import outside_legend, palette, plot_curves
from robot.previs.figure_file import save_figure
from robot.previs.mcap_read import mcap_rows

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Table:
    """Numeric columns by name (blank / null / text → NaN) and the ``state`` column."""

    columns: dict[str, Array]
    states: tuple[str, ...]
    source: str

    def joints(self, prefix: str) -> list[str]:
        return [c[len(prefix):] for c in self.columns if c.startswith(prefix)]


def _num(v: Any) -> float:
    if v is None or v == "" or isinstance(v, bool):
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def read_table(path: str | Path) -> Table:
    """Read a .csv, .jsonl or .mcap file of rows into columns; ConfigError (one line naming the
    file, the line and the column) unless it has at least two rows, a finite ``t`` in each
    and only plain values (no NUL byte, no nested JSON)."""
    p = Path(path)
    if p.suffix == ".mcap":                     # robot/loop/mcap_recorder.py
        rows = mcap_rows(p)
        names = list(rows[0]) if rows else []
    else:
        rows, names = _text_rows(p)
    if rows and p.suffix == ".jsonl" and "take" in rows[0]:
        rows, names = _take_rows(rows)
    if not rows or "t" not in names:
        raise ConfigError(f"{path}: no rows with a 't' column; expected a `biped walk "
                          "--record` or `biped curves` file")
    _check_rows(p, rows)
    cols = {n: np.array([_num(r.get(n)) for r in rows]) for n in names if n != "state"}
    states = tuple(str(r.get("state", "")) for r in rows)
    return Table(cols, states, str(p))


def _text_rows(p: Path) -> tuple[list[dict[str, Any]], list[str]]:
    path = p
    try:
        with p.open(newline="") as f:
            if p.suffix == ".jsonl":
                rows = [_json_row(p, k, line) for k, line in enumerate(f, 1) if line.strip()]
                names = list(rows[0]) if rows else []
            elif p.suffix == ".csv":
                reader = csv.reader(f)
                names = next(reader, [])
                rows = [dict(zip(names, r, strict=False)) for r in reader]
            else:
                raise ConfigError(f"{path}: unknown format {p.suffix!r}; valid: .csv, .jsonl, "
                                  ".mcap")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (UnicodeDecodeError, csv.Error, OSError) as e:
        raise ConfigError(f"{path}: not a valid record file: {e}") from None
    return rows, names


def _json_row(p: Path, k: int, line: str) -> dict[str, Any]:
    """Line ``k`` of a .jsonl record: a flat JSON object."""
    row = parse_json(line, where=f"{p}: line {k}")
    if not isinstance(row, dict):
        raise ConfigError(f"{p}: line {k}: expected a JSON object (one row), got "
                          f"{type(row).__name__}")
    return row


def _check_rows(p: Path, rows: list[dict[str, Any]]) -> None:
    """At least two rows; plain values only; ``t`` a finite number in every row."""
    if len(rows) < 2:
        raise ConfigError(f"{p}: {len(rows)} row; a plot needs at least 2")
    for k, row in enumerate(rows, 1):
        for name, v in row.items():
            if isinstance(v, dict | list) or (isinstance(v, str) and "\0" in v):
                raise ConfigError(f"{p}: row {k}: column {name!r}: expected a number or a "
                                  "word, got " + ("a NUL byte" if isinstance(v, str) else
                                                  f"a nested {type(v).__name__}"))
        if not math.isfinite(_num(row.get("t"))):
            raise ConfigError(f"{p}: row {k}: column 't': expected a finite time [s], got "
                              f"{str(row.get('t'))[:40]!r}")


def _take_rows(rows: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], list[str]]:
    """A take (robot/motion/takes.py) as record rows: its stream lines' t, state and the
    commanded angles as cmd_<joint> (a take keeps no read-back)."""
    joints = rows[0].get("joints") or []
    out = [{"t": r.get("t"), "state": r.get("state", ""),
            **{f"cmd_{j}": v for j, v in zip(joints, r.get("q") or [], strict=False)}}
           for r in rows[1:] if isinstance(r, dict) and "tick" in r]
    return out, ["t", "state", *(f"cmd_{j}" for j in joints)]


def kind_of(table: Table) -> str:
    """"record" (cmd_/present_ columns) or "curves" (paper channels and q_ columns)."""
    if table.joints("cmd_"):
        return "record"
    if table.joints("q_") and all(c in table.columns for c in CHANNELS):
        return "curves"
    raise ConfigError(f"{table.source}: neither a run record (cmd_<joint> columns) nor a "
                      "curves file (paper channels and q_<joint> columns)")


def plot_file(path: str | Path, out: str | Path) -> str:
    """Plot ``path`` to the PNG ``out``; returns the detected kind."""
    table = read_table(path)
    kind = kind_of(table)
    if kind == "curves":
        names = tuple(table.joints("q_"))
        q = np.vstack([table.columns[f"q_{n}"] for n in names])
        plot_curves(out, table.columns["t"], {c: table.columns[c] for c in CHANNELS}, names,
                    q, title=f"curves {Path(path).name}")
    else:
        plot_record(table, out)
    return kind


def record_figure(table: Table) -> Any:
    """Commanded vs present joint positions (legs, arms), loop timing, temperatures, loads;
    every axis labelled with its unit, a colour per joint within a panel, legends outside."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = table.columns
    t = c["t"] - c["t"][0]
    names = table.joints("cmd_")
    groups = [(g, label) for label, g in limb_groups(names)]
    limbs = [(f"{side} leg", [n for n in g if n.startswith(s)]) for g, label in groups
             if label == "leg joints" for side, s in (("right", "r_"), ("left", "l_"))]
    limbs += [(label.removesuffix(" joints"), g) for g, label in groups if label != "leg joints"]
    loads = [(label, [n for n in g if f"load_{n}" in c]) for label, g in limbs]
    loads = [(label, g) for label, g in loads if g] or [("loads", [])]
    temps = [(label, [n for n in g if f"temp_{n}" in c]) for g, label in groups]
    temps = [(label, g) for label, g in temps if g] or [("temperatures", [])]
    panels = len(groups) + 1 + len(temps) + len(loads)
    fig, axes = plt.subplots(panels, 1, figsize=(14, 3.0 * panels), sharex=True,
                             layout="constrained")
    for ax, (group, label) in zip(axes, groups, strict=False):
        for n, col in zip(group, palette(len(group)), strict=True):
            ax.plot(t, c[f"cmd_{n}"], "-", color=col, lw=1.1, label=n)
            present = c.get(f"present_{n}")
            if present is not None and np.isfinite(present).any():
                ok = np.isfinite(present)
                ax.plot(t[ok], present[ok], ".", color=col, ms=2.5)
        ax.set_title(f"{label}: commanded (lines) vs present (dots)", loc="left", fontsize=10)
        ax.set_ylabel("angle [rad]")
        outside_legend(ax, n=len(group))
    timing = axes[len(groups)]
    errors = c.get("period_error_ms", np.zeros(len(t)))
    if not np.any(np.nan_to_num(errors)):   # an unpaced simulation: no wall clock to miss
        timing.text(0.5, 0.5, "no loop timing: the simulation ran unpaced, faster than real "
                    "time (run with --realtime to pace it to the wall clock)",
                    ha="center", va="center", transform=timing.transAxes, fontsize=9,
                    bbox={"facecolor": "white", "edgecolor": "0.7"}, zorder=5)
    timing.plot(t, errors, lw=0.8, color="tab:blue", label="period error")
    timing.set_ylabel("period error [ms]")
    if "overruns" in c:
        count = timing.twinx()
        count.plot(t, c["overruns"], lw=1.2, color="tab:red", label="overruns (cumulative)")
        count.set_ylabel("overruns [count]")
        timing.plot([], [], lw=1.2, color="tab:red", label="overruns (cumulative, right)")
    if len(t) > 1:
        dt = np.diff(t)
        rate = 1.0 / np.median(dt[dt > 0]) if (dt > 0).any() else 0.0
        timing.set_title(f"loop timing (median rate {rate:.0f} Hz, "
                         f"p99 period error {np.nanpercentile(errors, 99):.3f} ms)",
                         loc="left", fontsize=10)
    timing.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.06, 1.0), borderaxespad=0.0)
    first = len(groups) + 1
    panels_of = [(ax, "temp_", f"temperatures: {label}", g, "temperature [°C]")
                 for ax, (label, g) in zip(axes[first:], temps, strict=False)]
    panels_of += [(ax, "load_", f"loads: {label}", g, "load [% of max torque]")
                  for ax, (label, g) in zip(axes[first + len(temps):], loads, strict=True)]
    for ax, prefix, name, joints, unit in panels_of:
        for n, col in zip(joints, palette(len(joints)), strict=True):
            v = c[f"{prefix}{n}"]
            ok = np.isfinite(v)
            ax.plot(t[ok], v[ok], "-", color=col, lw=1.0, label=n)
        ax.set_title(name, loc="left", fontsize=10)
        ax.set_ylabel(unit)
        if joints:
            outside_legend(ax, n=len(joints))
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.set_xlabel("t [s]")
        ax.tick_params(labelbottom=True)
    fig.suptitle(f"run record {Path(table.source).name}")
    return fig


def plot_record(table: Table, out: str | Path) -> None:
    """The record figure (``record_figure``) as a PNG."""
    import matplotlib.pyplot as plt

    fig = record_figure(table)
    save_figure(fig, out)
    plt.close(fig)
