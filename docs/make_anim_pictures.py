"""The pictures of docs/animatronics.md: a greeting show on a robot with a head, a jaw and a
tail (written as BVH on the `biped export` skeleton, as a Blender rig of it would export),
imported, checked in physics (the check plot), filmed in the simulation (four frames), and
played in the panel with its soundtrack (headless Chromium, as docs/make_panel_screenshots.py).

Run: ``MUJOCO_GL=egl .venv/bin/python docs/make_anim_pictures.py [OUT_DIR]`` (default docs/)
"""

from __future__ import annotations

import math
import shutil
import sys
import tempfile
import wave
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from playwright.sync_api import sync_playwright

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from extra_robot import write_extra_robot  # noqa: E402
from panel_harness import ARGS, CHROMIUM  # noqa: E402

import robot.cli as cli  # noqa: E402
from robot.config.gait_file import load_gait  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.gait.engine import GaitEngine  # noqa: E402
from robot.loop.telemetry import Telemetry  # noqa: E402
from robot.motion.layered import LayeredEngine  # noqa: E402
from robot.motion.show import stream_sequence  # noqa: E402
from robot.motion.takes import read_take  # noqa: E402
from robot.panel.controller import BusSpec, LoopOptions, make_controller  # noqa: E402
from robot.panel.server import build_server, serve_in_thread  # noqa: E402
from robot.panel.studio import Studio  # noqa: E402
from robot.previs.bvh import write_bvh  # noqa: E402
from robot.run.run import Run  # noqa: E402
from robot.run.spec import RunOptions, RunSpec  # noqa: E402
from sim.mujoco.bus import MujocoBus  # noqa: E402

FPS, SECONDS = 30.0, 6.0


def greeting(robot_path: Path, out: Path) -> None:
    """The show as a BVH: standing, the right arm waves, the head turns and nods, the jaw
    talks, the tail wags."""
    robot = load_robot(str(robot_path))
    names = robot.joint_names
    t = np.arange(int(SECONDS * FPS) + 1) / FPS
    q = np.tile(GaitEngine(robot, load_gait("walk").params).start_pose(), (len(t), 1))
    up = np.clip(t / 1.0, 0, 1) * np.clip((SECONDS - t) / 1.0, 0, 1)    # in and out
    q[:, names.index("r_shoulder_pitch")] = -2.2 * up
    q[:, names.index("r_shoulder_roll")] = -0.3 * up - 0.25 * up * np.sin(2 * math.pi * t)
    q[:, names.index("r_elbow")] = -0.6 * up
    q[:, names.index("head_pan")] = 0.5 * np.sin(2 * math.pi * t / SECONDS)
    q[:, names.index("head_tilt")] = -0.2 * up
    q[:, names.index("jaw")] = 0.3 * np.abs(np.sin(3 * math.pi * t)) * up
    q[:, names.index("tail")] = 0.35 * np.sin(2 * math.pi * 1.5 * t)
    write_bvh(out, robot, q, 1 / FPS)


def film(robot_path: Path, take_path: Path, out: Path) -> None:
    """Four frames of the show in the simulation, side by side."""
    robot = load_robot(str(robot_path))
    take = read_take(take_path)
    bus = MujocoBus(robot)
    engine = LayeredEngine(robot, take.header.params, keyframes=stream_sequence(take),
                           walk=False)
    frames: list[np.ndarray] = []
    wanted = [1.2, 2.3, 3.4, 4.6]

    def grab(tel: Telemetry) -> None:
        if tel.state == "walking" and wanted and engine.time >= wanted[0]:
            wanted.pop(0)
            frames.append(bus.render(360, 400, "track"))
    spec = RunSpec(robot=robot, source=engine, bus=bus, observer=grab,
                   options=RunOptions(rate_hz=take.header.rate_hz, watch=False))
    with Run(spec) as run:
        run.stream()
    iio.imwrite(out, np.concatenate(frames, axis=1))


def panel(robot_path: Path, takes: Path, out: Path) -> None:
    robot = load_robot(str(robot_path))
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 preset="walk")
    studio = Studio(controller, takes_dir=takes, keys_dir=takes.parent / "keys")
    server = build_server(controller, port=0, studio=studio)
    _, base = serve_in_thread(server)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=[
                *ARGS, "--autoplay-policy=no-user-gesture-required"])
            page = browser.new_page(viewport={"width": 1400, "height": 950})
            page.goto(base)
            page.wait_for_selector("#takes option[value=greeting]", state="attached")
            page.select_option("#takes", "greeting")
            page.click("#play")
            for _ in range(300):       # (the page's CSP refuses wait_for_function's eval)
                clock = page.evaluate("showClock()")
                if clock["playing"] and clock["show"] > 2.5:
                    break
                page.wait_for_timeout(100)
            page.evaluate("window.scrollTo(0, 0)")          # the header: "▶ greeting"
            page.screenshot(path=str(out), full_page=False)
            browser.close()
    finally:
        server.shutdown()
        server.server_close()
        controller.emergency_stop()
        controller.shutdown()


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp())
    robot_path = write_extra_robot(work)
    takes = work / "takes"
    takes.mkdir()
    greeting(robot_path, work / "greeting.bvh")
    n = int(SECONDS * 8000)
    with wave.open(str(takes / "greeting.wav"), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(8000)
        w.writeframes((0.2 * np.sin(2 * math.pi * 440 * np.arange(n) / 8000) * 32767)
                      .astype("<i2").tobytes())
    take = takes / "greeting.take.jsonl"
    assert cli.main(["import", str(work / "greeting.bvh"), "--robot", str(robot_path),
                     "--out", str(take), "--audio", "greeting.wav"]) == 0
    assert cli.main(["play", str(take), "--robot", str(robot_path),
                     "--check-plot", str(out / "anim-check.png")]) in (0, 1)
    film(robot_path, take, out / "anim-frames.png")
    panel(robot_path, takes, out / "anim-panel.png")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent)
