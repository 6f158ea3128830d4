"""The pictures where a new user stumbled: `biped plot` of a take, the loop-timing panel of
an unpaced simulation, channels that lie on top of each other, the rig unit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take
from robot.previs.curves import curves_figure
from robot.previs.plots import read_table, record_figure


def test_plot_draws_a_take(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    take = tmp_path / "walk.take.jsonl"
    assert cli.main(["walk", "--seconds", "1", "--record", str(take)]) == 0
    out = tmp_path / "take.png"
    assert cli.main(["plot", str(take), "--out", str(out)]) == 0
    assert out.stat().st_size > 10_000
    table = read_table(take)
    recorded = read_take(take)
    assert np.allclose(table.columns["cmd_r_knee"],
                       recorded.q[:, recorded.header.joints.index("r_knee")])


def test_an_unpaced_sim_says_why_it_has_no_loop_timing(tmp_path: Path) -> None:
    record = tmp_path / "run.csv"
    assert cli.main(["walk", "--seconds", "1", "--record", str(record)]) == 0
    fig = record_figure(read_table(record))
    timing = next(ax for ax in fig.axes if ax.get_title(loc="left").startswith("loop timing"))
    assert any("unpaced" in t.get_text() for t in timing.texts)


def test_equal_channels_are_drawn_so_both_show() -> None:
    robot = load_robot()
    t = np.arange(0, 3, 0.01)
    channels, q = GaitEngine(robot, load_gait("walk").params).curves(t)
    fig = curves_figure(t, channels, robot.joint_names, q, title="walk")
    for ax in fig.axes[:3]:
        lines = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
        for ln in lines:
            label = ln.get_label()
            if " (= " in label:         # said to equal another: it does, and is dashed
                other = label.split(" (= ")[1].rstrip(")")
                assert np.allclose(ln.get_ydata(), channels[other])
                assert ln.get_linestyle() == "--"
        plain = [ln for ln in lines if " (= " not in ln.get_label()]
        for i, a in enumerate(plain):   # no plain line hides another
            for b in plain[i + 1:]:
                assert not np.allclose(a.get_ydata(), b.get_ydata()), (a.get_label(),
                                                                       b.get_label())
    assert "rig units:" in fig._suptitle.get_text()
