"""Previs clips: walk a gait on the MuJoCo bus and film it with the tracking camera.

The Streamer runs the gait on simulation time (faster than real time); its observer grabs
a frame whenever the clock passes the next video frame time, so the clip plays at 1x.
Frames are written with imageio: .mp4 through imageio-ffmpeg's bundled ffmpeg (H.264),
.gif through Pillow.
"""

from __future__ import annotations

import errno
import logging
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from robot.bus.servo_map import ServoMap
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.files.atomic import replacing
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer, Telemetry
from sim.mujoco.bus import MujocoBus

log = logging.getLogger(__name__)

FORMATS = (".mp4", ".gif")
Frame = npt.NDArray[np.uint8]


@dataclass(frozen=True)
class ClipSpec:
    """seconds: clip length [s]; width, height: [px]; fps: video frames per second;
    rate_hz: control rate [Hz]; camera: MuJoCo camera name."""

    seconds: float = 5.0
    width: int = 640
    height: int = 360
    fps: float = 30.0
    rate_hz: float = 200.0
    camera: str = "track"

    @property
    def frames(self) -> int:
        return max(1, int(round(self.seconds * self.fps)))


@dataclass(frozen=True)
class ClipResult:
    path: Path
    frames: int
    seconds: float
    fell: bool


def check_output(path: str | Path, spec: ClipSpec) -> Path:
    """Validate the output format and frame size before any simulation runs."""
    p = Path(path)
    if p.suffix.lower() not in FORMATS:
        raise ConfigError(f"--out {path}: unknown video format {p.suffix!r}; valid: "
                          f"{', '.join(FORMATS)}")
    if not (16 <= spec.width <= 1920 and 16 <= spec.height <= 1080):
        raise ConfigError(f"--width/--height {spec.width}x{spec.height}: expected 16..1920 "
                          f"x 16..1080 px (the offscreen buffer's size)")
    if p.suffix.lower() == ".mp4" and (spec.width % 2 or spec.height % 2):
        raise ConfigError(f"--width/--height {spec.width}x{spec.height}: mp4 (H.264) needs "
                          "even sizes")
    return p


def _writer(path: Path, fps: float) -> Any:
    import imageio.v2 as imageio

    if path.suffix.lower() == ".mp4":
        return imageio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                  quality=7, macro_block_size=2, pixelformat="yuv420p",
                                  ffmpeg_log_level="quiet")   # its failures: _check_clip
    return None


def _check_clip(path: Path, frames: int) -> None:
    """OSError unless ffmpeg reads ``frames`` frames back from the clip it wrote: imageio
    does not look at how ffmpeg exited (a full disk as it wrote the trailer: a clip that
    does not play, and no error)."""
    import imageio_ffmpeg

    try:
        got = imageio_ffmpeg.count_frames_and_secs(str(path))[0]
    except RuntimeError:                     # ffmpeg cannot read it at all
        got = 0
    if got != frames:
        full = os.statvfs(path.parent).f_bavail == 0
        raise OSError(errno.ENOSPC if full else errno.EIO,
                      os.strerror(errno.ENOSPC) if full
                      else f"ffmpeg wrote a clip of {got} frames, not {frames}", str(path))


def render_walk(robot: RobotConfig, params: GaitParams, out: str | Path, *,
                spec: ClipSpec = ClipSpec(), progress: bool = True) -> ClipResult:
    """Walk ``params`` on a fresh MujocoBus and write ``spec.frames`` frames to ``out``
    (whole, robot.files.atomic; OSError if it cannot be written)."""
    path = check_output(out, spec)
    with replacing(path) as temp:    # whole or not at all (a device: copied at the end)
        count, fell = _render(robot, params, temp, spec=spec, progress=progress,
                              label=path.name)
    log.info("wrote %s: %d frames at %g fps", path, count, spec.fps)
    return ClipResult(path=path, frames=count, seconds=count / spec.fps, fell=fell)


def _render(robot: RobotConfig, params: GaitParams, path: Path, *, spec: ClipSpec,
            progress: bool, label: str) -> tuple[int, bool]:
    """Walk and write the clip to ``path``; (frames written, whether the robot fell).
    OSError if the clip cannot be written."""
    from tqdm import tqdm

    from sim.mujoco.metrics import WalkMonitor

    n = spec.frames
    frames: list[Frame] = []
    writer = _writer(path, spec.fps)
    bus = MujocoBus(robot)
    bar = tqdm(total=n, unit="frame", desc=f"render {label}", disable=not progress)
    failed: list[OSError] = []
    try:
        with bus:
            monitor = WalkMonitor(standing_height=bus.standing_height)
            t0 = bus.clock.now()
            box: dict[str, Any] = {"next": t0, "count": 0}

            def grab(tel: Telemetry) -> None:
                monitor.update(tel.t, *bus.base_pose(), bus.upright_angle())
                if box["count"] >= n or tel.t + 1e-9 < box["next"]:
                    return
                frame = bus.render(spec.width, spec.height, camera=spec.camera)
                if writer is not None:
                    try:
                        writer.append_data(frame)
                    except OSError as e:       # ffmpeg could not write: end the clip
                        failed.append(e)
                        streamer.request_stop("clip cannot be written")
                        return
                else:
                    frames.append(frame.copy())
                box["count"] += 1
                box["next"] = t0 + box["count"] / spec.fps
                bar.update(1)
                if box["count"] >= n:
                    streamer.request_stop("clip complete")
            streamer = Streamer(ServoMap(robot), bus, GaitEngine(robot, params),
                                rate_hz=spec.rate_hz, observer=grab)
            # A generous gait time: the observer stops the run once the clip is full.
            streamer.run(seconds=spec.seconds + 2.0 * math.pi / max(params.omega, 1e-3) + 1)
    finally:
        bar.close()
        if writer is not None:
            writer.close()
    if failed:
        raise failed[0]
    if writer is None:
        _write_gif(path, frames, spec.fps)
    else:
        _check_clip(path, int(box["count"]))
    return int(box["count"]), monitor.fell


def _write_gif(path: Path, frames: list[Frame], fps: float) -> None:
    import imageio.v3 as iio

    iio.imwrite(path, np.stack(frames), extension=".gif", plugin="pillow",
                duration=1000.0 / fps, loop=0)
