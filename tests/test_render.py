"""`biped render`: a readable clip of the requested length whose frames show a moving robot."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as imageio
import numpy as np
import pytest

from robot.cli import main
from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from sim.mujoco.render import ClipSpec, check_output, render_walk

SECONDS, FPS = 1.5, 10


def read_frames(path: Path) -> np.ndarray:
    if path.suffix == ".mp4":
        with imageio.get_reader(path, format="FFMPEG") as r:
            return np.stack([np.asarray(f) for f in r])
    return np.stack([np.asarray(f)[..., :3] for f in imageio.mimread(path)])


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_render_writes_a_moving_clip(tmp_path: Path, suffix: str,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / f"walk{suffix}"
    assert main(["render", "--gait", "walk", "--seconds", str(SECONDS), "--fps", str(FPS),
                 "--width", "160", "--height", "96", "--out", str(out)]) == 0
    assert f"{int(SECONDS * FPS)} frames" in capsys.readouterr().out
    frames = read_frames(out)
    assert frames.shape[1:] == (96, 160, 3)
    assert abs(len(frames) - SECONDS * FPS) <= 1
    assert all(f.std() > 10 for f in frames)  # not blank
    diffs = [np.abs(frames[i + 1].astype(int) - frames[i].astype(int)).mean()
             for i in range(len(frames) - 1)]
    assert np.mean(diffs) > 0.2 and np.abs(frames[-1].astype(int) - frames[0]).mean() > 0.5


def test_render_walk_api_counts_frames(tmp_path: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    spec = ClipSpec(seconds=0.5, width=64, height=48, fps=8)
    res = render_walk(robot, load_gait("walk").params, tmp_path / "a.gif", spec=spec,
                      progress=False)
    assert res.frames == 4 and not res.fell and res.path.stat().st_size > 1000


@pytest.mark.parametrize("name, spec, needle", [
    ("x.avi", ClipSpec(), "unknown video format"),
    ("x.mp4", ClipSpec(width=161, height=96), "even"),
    ("x.gif", ClipSpec(width=5000, height=96), "16..1920"),
])
def test_bad_output_refused_before_simulating(name: str, spec: ClipSpec, needle: str) -> None:
    with pytest.raises(ConfigError, match=needle):
        check_output(name, spec)
    assert main(["render", "--out", name, "--width", str(spec.width),
                 "--height", str(spec.height)]) == 2
