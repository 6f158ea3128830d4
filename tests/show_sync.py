"""Measuring a show's audio sync in the panel (headless Chromium): a show take with a
soundtrack (an arm show imported from a BVH, a tone), the panel serving it, and reads of
the page's <audio> clock against the take's time at the same instant (the loop process
stamps each tick's take time with its wall clock; the page says when it read). Used by
tests/test_panel_show.py (a short run, a loose bound that catches a broken follower)
and docs/show_sync.py (the 30 s measurement)."""

from __future__ import annotations

import math
import time
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from playwright.sync_api import Browser
from waiting import sleep_until, wait_for

import robot.cli as cli
from robot.panel.controller import PanelController

FPS, OFFSET, RATE = 30.0, 0.5, 8000
#: Chromium starts media without a click (a test has none).
AUTOPLAY = "--autoplay-policy=no-user-gesture-required"
#: Time between two reads of the page's audio clock [s] (five a second).
READ_PERIOD_S = 0.2


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


@dataclass(frozen=True)
class Sync:
    """Per read while the audio plays [ms]: ``audio`` the audio's clock less the take's
    time at the instant of the read; ``estimate`` the page's own estimate of the take's
    time less the take's time (what the follower steers to); the reads' page wall times
    [s]; the audio's playback rate and the seeks the page had made by then; ``span`` [s]
    of take time covered."""

    audio: list[float]
    estimate: list[float]
    at: list[float]
    rate: list[float]
    seeks: list[int]
    span: float


def measure(controller: PanelController, base: str, browser: Browser, seconds: float,
            wait: float = 20.0, tune: dict[str, float] | None = None) -> Sync:
    """Play the show from the page and compare, read by read, the page's <audio> clock
    with the take's time at the same instant: the page says when (its wall clock) it read
    the audio; the loop process stamps each tick's take time with its wall clock (the same
    machine's clock); the take's time at the read is interpolated between the stamped
    ticks fetched just before and just after the read. Reads count from the take time at
    which the soundtrack begins (its offset; before it the audio's clock has nothing to
    run on: the page may start the element a little early, its clock held at 0). ``tune``: the page's follower
    settings to change (robot/panel/static/studio.js ``showTune``). Leaves the page open
    until the take ends."""
    page = browser.new_page()
    page.goto(base)
    if tune:
        page.evaluate("(t) => Object.assign(window.showTune, t)", tune)
    page.wait_for_selector("#takes option[value=show]", state="attached")
    page.select_option("#takes", "show")
    page.click("#play")

    def stamped() -> tuple[float, float] | None:
        """(take time [s], wall time of its tick [s]), asked of the loop process now."""
        s = controller.loop_state(max_age=0.0)
        show = s.get("show") if s["running"] else None
        if not show or not show["playing"] or show["at"] is None:
            return None
        return float(show["t"]), float(show["at"])
    wait_for(lambda: bool(page.evaluate("showClock().playing")), timeout_s=wait, every_s=0.05)
    first = stamped() or (0.0, 0.0)
    audio: list[float] = []
    estimate: list[float] = []
    at: list[float] = []
    rate: list[float] = []
    seeks: list[int] = []
    next_read = time.monotonic()
    while (a := stamped()) is not None and a[0] < first[0] + seconds:
        clock = page.evaluate("showClock()")
        b = stamped()
        if b is None:
            break
        w = clock["at"] / 1000.0
        # between the ticks stamped before and after the read; on a loaded machine both
        # asks may find the same tick: then from it at the take's rate (1 s per s)
        take = (a[0] + (w - a[1]) * (b[0] - a[0]) / (b[1] - a[1]) if b[1] > a[1]
                else b[0] + (w - b[1]))
        if clock["playing"] and take >= OFFSET:   # the soundtrack has begun
            audio.append(1000 * (clock["audio"] + OFFSET - take))
            estimate.append(1000 * (clock["show"] - take))
            at.append(w)
            rate.append(float(clock["rate"]))
            seeks.append(int(clock["seeks"]))
        next_read += READ_PERIOD_S          # reads on absolute deadlines: a late one is not
        sleep_until(next_read)              # followed by a longer gap
    span = (stamped() or (first[0] + seconds, 0.0))[0] - first[0]
    page.close()
    return Sync(audio, estimate, at, rate, seeks, span)
