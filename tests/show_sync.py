"""Measuring a show's audio sync in the panel (headless Chromium): a show take with a
soundtrack (an arm show imported from a BVH, a tone), the panel serving it, and reads of
the page's <audio> clock against the take's time (the engine's, asked of the panel's loop
process just before and after each read of the page). Used by tests/test_panel_show.py (a short run, a
loose bound that catches a broken follower) and docs/show_sync.py (the 30 s measurement)."""

from __future__ import annotations

import math
import time
import wave
from pathlib import Path

import numpy as np
from playwright.sync_api import Browser

import robot.cli as cli
from robot.panel.controller import PanelController

FPS, OFFSET, RATE = 30.0, 0.5, 8000
#: Chromium starts media without a click (a test has none).
AUTOPLAY = "--autoplay-policy=no-user-gesture-required"


def write_show(folder: Path, seconds: float) -> None:
    """``folder``/takes/show.take.jsonl: ``seconds`` of arm motion, its audio from 0.5 s."""
    takes = folder / "takes"
    takes.mkdir(parents=True, exist_ok=True)
    n = int(seconds * FPS)
    lines = ["HIERARCHY", "ROOT pelvis", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation",
             "JOINT chest", "{", "OFFSET 0 30 0", "CHANNELS 3 Zrotation Xrotation Yrotation",
             "JOINT r_shoulder", "{", "OFFSET -10 0 0",
             "CHANNELS 3 Zrotation Xrotation Yrotation",
             "End Site", "{", "OFFSET 0 -20 0", "}", "}", "}", "}",
             "MOTION", f"Frames: {n}", f"Frame Time: {1 / FPS:.6f}"]
    lines += [f"0 45 0 0 0 0 0 0 0 0 {-30 * math.sin(k / FPS) ** 2:.4f} 0" for k in range(n)]
    (folder / "arm.bvh").write_text("\n".join(lines) + "\n")
    t = np.arange(int((seconds + 2) * RATE)) / RATE
    with wave.open(str(takes / "song.wav"), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(RATE)
        w.writeframes((0.2 * np.sin(2 * math.pi * 330 * t) * 32767).astype("<i2").tobytes())
    assert cli.main(["import", str(folder / "arm.bvh"), "--out", str(takes / "show.take.jsonl"),
                     "--audio", "song.wav", "--audio-offset", str(OFFSET)]) == 0


def measure(controller: PanelController, base: str, browser: Browser, seconds: float,
            wait: float = 20.0) -> tuple[list[float], float]:
    """Play the show from the page; (audio - take time [ms] per read while the audio
    plays, seconds of take time covered). Leaves the page open until the take ends."""
    page = browser.new_page()
    page.goto(base)
    page.wait_for_selector("#takes option[value=show]", state="attached")
    page.select_option("#takes", "show")
    page.click("#play")

    def take_time() -> float | None:
        s = controller.loop_state(max_age=0.0)      # asked of the loop process now
        return s.get("engine_t") if s["running"] else None
    end = time.monotonic() + wait
    while not page.evaluate("showClock().playing") and time.monotonic() < end:
        time.sleep(0.05)
    first = take_time() or 0.0
    errors: list[float] = []
    while (now := take_time()) is not None and now < first + seconds:
        t0 = take_time()
        clock = page.evaluate("showClock()")
        t1 = take_time()
        if t0 is None or t1 is None:
            break
        # A read within a few ticks: the take's time is asked of the loop process (a
        # round trip each), so the bracket is wider than a tick on a busy machine.
        if clock["playing"] and t1 - t0 <= 0.03:
            errors.append(1000 * (clock["audio"] + OFFSET - (t0 + t1) / 2))
        time.sleep(0.1)
    span = (take_time() or first + seconds) - first
    page.close()
    return errors, span
