"""End to end in real headless Chromium (Debian's, driven by Playwright): the panel on the
MuJoCo bus; drag a slider and see it reach the running loop; stop, start, emergency stop;
token mode served on every address, opened at the LAN URL a phone would use.

Waits use Playwright's ``expect`` (no string evaluation: the page's CSP forbids eval)."""

from __future__ import annotations

import os
import re
import signal
import time
from collections.abc import Iterator

import numpy as np
import pytest
from panel_harness import served_panel, wait_for
from playwright.sync_api import Browser, Page, expect

from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, LoopOptions, PanelController, make_controller
from robot.panel.server import build_server, panel_url, serve_in_thread

pytest_plugins = ("panel_harness",)  # the browser fixture


@pytest.fixture
def running() -> Iterator[tuple[PanelController, str]]:
    """A walking panel of its own for each test (no test sees a run another one ended)."""
    with served_panel() as (controller, base):
        controller.start()
        yield controller, base


@pytest.fixture
def page(running: tuple[PanelController, str], browser: Browser) -> Iterator[Page]:
    pg = browser.new_page(viewport={"width": 1400, "height": 950})
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.on("console", lambda m: "Content Security Policy" in m.text and errors.append(m.text))
    pg.goto(running[1])
    pg.wait_for_selector("#range-Slgt_R")
    yield pg
    pg.close()
    assert not errors, errors


def hip_pitch_swing(controller: PanelController, seconds: float) -> float:
    """Peak-to-peak of the commanded right hip pitch over ``seconds`` [rad]."""
    i = controller.robot.joint_names.index("r_hip_pitch")
    seen: list[float] = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        q = controller.state()["q_cmd"]
        if q:
            seen.append(q[i])
        time.sleep(0.01)
    return float(np.ptp(seen))


def test_slider_reaches_the_running_loop(running: tuple[PanelController, str],
                                         page: Page) -> None:
    controller, _ = running
    assert page.input_value("#preset") == "walk"
    assert wait_for(lambda: controller.state()["state"] == "walking")
    s0 = controller.live_params().Slgt_R  # the preset's (about 0.5; range [0, 3])
    s1 = s0 + 0.7
    cycle = controller.live_params().cycle_s
    before = hip_pitch_swing(controller, cycle)
    slider = page.locator("#range-Slgt_R")
    slider.scroll_into_view_if_needed()  # above the fixed bar of run controls
    box = slider.bounding_box()
    assert box is not None
    y = box["y"] + box["height"] / 2
    # Drag the thumb from s0 to s1 (the thumb's centre is inset by half its width, 14 px,
    # at the ends).
    def x_of(v: float) -> float:
        return box["x"] + 14 + (box["width"] - 28) * v / 3
    page.mouse.move(x_of(s0), y)
    page.mouse.down()
    page.mouse.move(x_of((s0 + s1) / 2), y, steps=4)
    page.mouse.move(x_of(s1), y, steps=4)
    page.mouse.up()
    assert wait_for(lambda: abs(controller.live_params().Slgt_R - s1) < 0.1, 3.0), \
        controller.live_params().Slgt_R
    # The drag's last input events may still be in flight: wait until page, controller and
    # loop agree on the final value.
    assert wait_for(lambda: controller.live_params().Slgt_R == controller.params.Slgt_R
                    and abs(float(page.input_value("#num-Slgt_R"))
                            - controller.live_params().Slgt_R) < 0.01, 3.0), \
        (page.input_value("#num-Slgt_R"), controller.live_params().Slgt_R)
    after = hip_pitch_swing(controller, cycle)
    assert after > before * 1.3 + 0.02, (before, after)


def test_number_box_refuses_out_of_range(running: tuple[PanelController, str],
                                         page: Page) -> None:
    controller, _ = running
    before = controller.params
    page.fill("#num-vM", "7")
    page.press("#num-vM", "Enter")
    page.wait_for_selector("#message.error")
    assert "vM = 7 is outside [0, 2]" in page.inner_text("#message")
    assert controller.params == before
    expect(page.locator("#num-vM")).to_have_value(f"{before.vM:g}")


def test_stop_start_estop_buttons(running: tuple[PanelController, str], page: Page) -> None:
    controller, _ = running
    assert wait_for(lambda: controller.state()["state"] == "walking")
    seen: set[str] = set()
    page.click("#stop")
    assert wait_for(lambda: seen.add(controller.state()["state"]) or not controller.running)
    assert seen & {"ramp_out", "rest"} and controller.state()["state"] == "stopped"
    expect(page.locator("#state")).to_have_text(re.compile("^stopped"))
    page.click("#start")
    assert wait_for(lambda: controller.state()["state"] == "walking")
    expect(page.locator("#state")).to_have_text("walking")
    assert all(controller.state()["torque"])  # what the wire was told: torque on
    page.click("#estop")
    assert controller.wait(1.0)
    assert controller.state()["state"] == "estop"
    assert not any(controller.state()["torque"])
    expect(page.locator("#state")).to_have_text(re.compile("^estop"))


def test_token_mode_from_a_phone(browser: Browser) -> None:
    """Served on 0.0.0.0 with a token: the printed LAN URL shows the sliders and drives
    the loop; without the token the page loads but the API refuses it."""
    robot = load_robot(DEFAULT_ROBOT)
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5))
    server = build_server(controller, host="0.0.0.0", port=0, token="phone-t0ken")
    serve_in_thread(server)
    url = panel_url("0.0.0.0", int(server.server_address[1]))
    assert "0.0.0.0" not in url
    pg = browser.new_page(viewport={"width": 412, "height": 915})  # a phone's
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    statuses: dict[str, int] = {}
    pg.on("response", lambda r: statuses.setdefault(r.url.split("?")[0], r.status))
    try:
        pg.goto(url)  # no token: the page and its assets load, every API call is refused
        expect(pg.locator("#message")).to_contain_text("token")
        assert pg.locator("#range-Slgt_R").count() == 0
        assert statuses[url] == statuses[url + "panel.js"] == statuses[url + "panel.css"] == 200
        assert statuses[url + "api/params"] == 401
        pg.goto(url + "?token=phone-t0ken")
        pg.wait_for_selector("#range-Slgt_R")  # in the phone's simple view too
        expect(pg.locator("#state")).to_have_text(re.compile("^idle"))
        pg.click("#start")
        assert wait_for(lambda: controller.state()["state"] == "walking")
        expect(pg.locator("#state")).to_have_text("walking")
        pg.click("#estop")
        assert controller.wait(1.0) and controller.state()["state"] == "estop"
        assert not errors, errors
    finally:
        pg.close()
        server.shutdown()
        server.server_close()
        controller.shutdown(timeout=2.0)


def test_a_loop_that_does_not_answer_is_shown(running: tuple[PanelController, str],
                                              page: Page) -> None:
    """The loop process frozen: the page says so (state and the fault row), never a
    stale "walking"; when it runs again the page follows it."""
    controller, _ = running
    expect(page.locator("#state")).to_have_text("walking")
    loop = controller.pid
    assert loop is not None
    os.kill(loop, signal.SIGSTOP)
    try:
        expect(page.locator("#state")).to_have_text(re.compile("^fault"), timeout=15000)
        expect(page.locator("#loop")).to_contain_text("did not answer")
    finally:
        os.kill(loop, signal.SIGCONT)
    expect(page.locator("#state")).to_have_text("walking", timeout=15000)
