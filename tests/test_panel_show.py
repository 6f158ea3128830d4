"""A show take with a soundtrack in the panel, in Debian's headless Chromium: the page's
<audio> element plays the take's sound file (served with byte ranges by /api/show/audio, so
it can seek) from the audio's offset and follows the take's time on the robot; the page
says when the take has finished. A short run with a loose bound that catches a broken
follower (an audio that cannot seek sat seconds behind); the 30 s figure is measured by
docs/show_sync.py, not asserted in a test on a shared machine."""

from __future__ import annotations

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
        held = np.abs(got.audio[5:])
        assert float(np.median(held)) < 100.0, got.audio
        assert wait_for(lambda: not controller.running, timeout=15.0)


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
