"""The pictures a person reads: in the curves plot and the record plot, a colour per line
that does not repeat within a panel, legends beside the data (never over it), and a unit
on every axis."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from matplotlib.colors import to_hex

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.previs.curves import curves_figure
from robot.previs.plots import read_table, record_figure

UNIT = re.compile(r"\[[^\]]+\]")


def check(fig: Any) -> None:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        labelled = [line for line in ax.get_lines() if not line.get_label().startswith("_")]
        colours = [to_hex(line.get_color()) for line in labelled]
        assert len(colours) == len(set(colours)), (ax.get_title(), colours)
        assert UNIT.search(ax.get_ylabel()), (ax.get_title(), ax.get_ylabel())
        legend = ax.get_legend()
        twin = ax.get_xlabel() == ""  # a twinx shares the x axis of its host
        if not twin:
            assert UNIT.search(ax.get_xlabel()), ax.get_title()
        if legend is not None:
            box = legend.get_window_extent(renderer)
            data = ax.get_window_extent(renderer)
            assert box.x0 >= data.x1, (ax.get_title(), box, data)  # right of the data


@pytest.mark.parametrize("name", ["biped18-dynamixel", "biped12-legs"])
def test_curves_plot(name: str) -> None:
    any_robot = load_robot(name)
    times = np.linspace(0, 3, 301)
    ch, q = GaitEngine(any_robot, load_gait("walk").params).curves(times)
    fig = curves_figure(times, ch, any_robot.joint_names, q, title="t")
    check(fig)
    assert len(fig.axes) == 4 + (1 if any_robot.has_arms else 0)


def test_record_plot(tmp_path: Path) -> None:
    out = tmp_path / "r.csv"
    assert cli.main(["walk", "--seconds", "1", "--record", str(out)]) == 0
    fig = record_figure(read_table(out))
    check(fig)
    twin = [ax for ax in fig.axes if ax.get_ylabel() == "overruns [count]"]
    assert twin  # the cumulative count has its own axis, not the one in ms
    assert any(ax.get_ylabel() == "period error [ms]" for ax in fig.axes)
    names = load_robot().joint_names
    assert len(fig.axes[0].get_legend().get_texts()) == sum(
        1 for n in names if "shoulder" not in n and "elbow" not in n)


@pytest.mark.parametrize("cmd", [["curves", "--seconds", "1", "--out", "c.csv", "--plot", "c.png"]])
def test_plots_are_written(tmp_path: Path, cmd: list[str], monkeypatch: pytest.MonkeyPatch
                           ) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(cmd) == 0
    assert (tmp_path / "c.png").stat().st_size > 10_000
