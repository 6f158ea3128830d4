"""A show take with a soundtrack in the panel, in Debian's headless Chromium: the page's
<audio> element plays the take's sound file (served with byte ranges by /api/show/audio, so
it can seek) from the audio's offset and follows the take's time on the robot; the page
says when the take has finished. A short run with a loose bound that catches a broken
follower (an audio that cannot seek sat seconds behind); the 30 s figure is measured by
docs/show_sync.py, not asserted in a test on a shared machine."""

from __future__ import annotations

import json
import re
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from panel_harness import ARGS, CHROMIUM, served_panel, wait_for
from playwright.sync_api import Browser, sync_playwright
from show_sync import AUTOPLAY, measure, write_show

from robot.panel.routes import byte_range


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=[*ARGS, AUTOPLAY])
        yield b
        b.close()


def test_byte_ranges_by_rfc_9110() -> None:
    data = bytes(range(100))
    assert byte_range(data, "audio/wav", "").status == 200
    part = byte_range(data, "audio/wav", "bytes=10-19")
    assert (part.status, part.body, part.headers["Content-Range"]) == \
        (206, data[10:20], "bytes 10-19/100")
    assert byte_range(data, "audio/wav", "bytes=90-").body == data[90:]
    assert byte_range(data, "audio/wav", "bytes=-5").body == data[95:]
    assert byte_range(data, "audio/wav", "bytes=200-").status == 416


def test_the_page_plays_the_take_s_audio_in_step(tmp_path: Path, browser: Browser) -> None:
    write_show(tmp_path, seconds=8.0)
    with served_panel(studio_dir=tmp_path) as (controller, base):
        got = measure(controller, base, browser, seconds=6.0)
        assert got.span >= 5.5 and len(got.audio) >= 10, (got.span, len(got.audio))
        assert float(np.median(np.abs(got.audio))) < 100.0, got.audio   # the start too
        assert wait_for(lambda: not controller.running, timeout=15.0)


def _with_cues(take: Path, cues: list[tuple[float, str]]) -> None:
    """Give the take's show cue markers (its header's ``show.cue``, robot/motion/show.py)."""
    lines = take.read_text().splitlines()
    header = json.loads(lines[0])
    header["show"]["cue"] = [{"t": t, "name": name} for t, name in cues]
    take.write_text("\n".join([json.dumps(header), *lines[1:]]) + "\n")


def test_the_state_says_what_the_show_is_doing(tmp_path: Path) -> None:
    """While a show take plays, the panel's state (from the loop process) is "playing"
    with the take's name, its time of its duration and the next cue; before and after,
    not; the time it reports runs with the show."""
    write_show(tmp_path, seconds=4.0)
    _with_cues(tmp_path / "takes" / "show.take.jsonl", [(1.0, "lights up"), (3.0, "bow")])
    doing = re.compile(r"playing take show (\d+\.\d) / 4\.0 s(, next cue '([a-z ]+)' at "
                       r"(\d\.\d) s)?$")
    with served_panel(studio_dir=tmp_path) as (controller, base):
        req = urllib.request.Request(base + "api/play", method="POST",
                                     data=json.dumps({"name": "show"}).encode(),
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=10) as r:
            assert r.status == 200
        seen: list[tuple[float, str | None]] = []

        def read() -> bool:
            s = controller.state()
            if s["state"] == "playing":
                m = doing.match(s["doing"] or "")
                assert m is not None, s["doing"]
                seen.append((float(m.group(1)), m.group(3)))
            else:
                assert s["doing"] is None, s
            return not controller.running and len(seen) > 0
        assert wait_for(read, timeout=30.0)
        times = [t for t, _ in seen]
        assert times == sorted(times) and times[0] < 1.0 and times[-1] > 3.0, times
        # The next cue by the time shown (rounded to 0.1 s: at a cue's time, either).
        assert all(cue in {("lights up" if x < 1.0 else "bow" if x < 3.0 else None)
                           for x in (t - 0.05, t + 0.05)} for t, cue in seen), seen
        assert {cue for _, cue in seen} == {"lights up", "bow", None}
        assert controller.state()["state"] != "playing"


def test_arrows_steer_with_a_slider_focused_and_the_status_line_says_what_happened(
        browser: Browser) -> None:
    with served_panel() as (controller, base):
        controller.start()
        page = browser.new_page(viewport={"width": 1400, "height": 950})
        page.goto(base)
        page.wait_for_selector("#range-Slgt_R")
        before = page.input_value("#range-Slgt_R")
        speed = controller.params.speed
        page.focus("#range-Slgt_R")
        page.keyboard.press("ArrowUp")              # the documented step: speed + 0.1
        assert wait_for(lambda: abs(controller.params.speed - (speed + 0.1)) < 1e-9)
        assert page.input_value("#range-Slgt_R") == before
        page.click("#stop")
        assert wait_for(lambda: page.text_content("#message") ==
                        "stop requested: ramping out to rest")
        page.keyboard.press("Escape")
        assert wait_for(lambda: page.text_content("#message") ==
                        "keyboard: emergency stop: torque off")
        page.close()
