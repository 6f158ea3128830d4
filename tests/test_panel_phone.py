"""The panel in real headless Chromium at a phone's size (390x844) and a desktop's: nothing
off-screen, the run controls always on screen and thumb-sized, labels in words beside the
paper's symbols, the simple and full views; a gamepad simulated through the Gamepad API
(``navigator.getGamepads`` replaced before the page loads, connect/disconnect events) and
the keyboard drive the running loop, and a gamepad that disconnects stops the walk."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from panel_harness import served_panel, wait_for
from playwright.sync_api import Browser, Page, expect

from robot.config.params import SPECS
from robot.panel.controller import PanelController
from robot.panel.labels import LABELS

PHONE = {"width": 390, "height": 844}
DESKTOP = {"width": 1400, "height": 950}
MIN_TOUCH_PX = 48

#: A standard-mapping gamepad the page's getGamepads() returns; the test moves its sticks.
FAKE_PAD = """
window.__pad = { id: "Test pad (STANDARD GAMEPAD)", index: 0, connected: true,
  mapping: "standard", timestamp: 0, axes: [0, 0, 0, 0],
  buttons: Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 })) };
window.__pads = [];
navigator.getGamepads = () => window.__pads;
"""

pytest_plugins = ("panel_harness",)  # the browser fixture


@pytest.fixture
def panel(tmp_path: Path) -> Iterator[tuple[PanelController, str]]:
    """A panel of its own for each test (a walk one test stops is no other test's state)."""
    with served_panel(studio_dir=tmp_path / "studio") as served:
        yield served


def open_page(browser: Browser, base: str, viewport: dict[str, int], *,
              init: str | None = None) -> tuple[Page, list[str]]:
    page = browser.new_page(viewport=viewport, has_touch=viewport is PHONE)
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("console", lambda m: "Content Security Policy" in m.text and errors.append(m.text))
    if init:
        page.add_init_script(init)
    page.goto(base)
    page.wait_for_selector("#range-speed", state="attached")
    return page, errors


def boxes(page: Page, selector: str) -> list[dict[str, float]]:
    """Bounding boxes of the visible elements matching ``selector`` (page coordinates)."""
    return page.eval_on_selector_all(selector, """els => els.filter(e => e.offsetParent)
        .map(e => { const r = e.getBoundingClientRect();
                    return { x: r.left + scrollX, y: r.top + scrollY, w: r.width, h: r.height,
                             id: e.id }; })""")


def assert_fits(page: Page, width: int) -> None:
    """No horizontal scrolling; every visible slider and button inside the width."""
    scroll_w = page.evaluate("document.scrollingElement.scrollWidth")
    assert scroll_w <= width, f"page is {scroll_w} px wide on a {width} px screen"
    for b in boxes(page, "input[type=range], button, select, input"):
        assert b["x"] >= 0 and b["x"] + b["w"] <= width + 0.5, b


def assert_run_controls_on_screen(page: Page, viewport: dict[str, int]) -> None:
    """After scrolling to the end and back to the middle, stop and the emergency stop are
    in the viewport and at least MIN_TOUCH_PX tall."""
    total = page.evaluate("document.scrollingElement.scrollHeight")
    assert total > viewport["height"] * 1.5  # there is something to scroll past
    for y in (total, total // 2):
        page.evaluate(f"window.scrollTo(0, {y})")
        # laid out and painted after the scroll: two animation frames
        page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        for sel in ("#estop", "#stop"):
            r = page.eval_on_selector(sel, "e => e.getBoundingClientRect().toJSON()")
            assert r["height"] >= MIN_TOUCH_PX, (sel, r)
            assert 0 <= r["top"] and r["bottom"] <= viewport["height"], (sel, y, r)
            assert 0 <= r["left"] and r["right"] <= viewport["width"], (sel, r)
    page.evaluate("window.scrollTo(0, 0)")


def test_phone_fits_and_keeps_the_stops_on_screen(panel: tuple[PanelController, str],
                                                 browser: Browser) -> None:
    _, base = panel
    page, errors = open_page(browser, base, PHONE)
    try:
        # A narrow screen opens on the simple view: steer, foot height, stride, crouch.
        expect(page.locator("body")).to_have_class(re.compile("simple"))
        shown = sorted(b["id"].removeprefix("range-") for b in boxes(page, "input[type=range]"))
        assert shown == sorted(["speed", "turn", "side_step", "Fhgt_R", "Fhgt_L", "Slgt_R",
                                "Slgt_L", "stance"])
        assert page.locator("#preset").is_visible()
        assert_fits(page, PHONE["width"])
        assert_run_controls_on_screen(page, PHONE)
        # Touch-sized slider thumbs.
        thumb = page.eval_on_selector("#range-speed", """e => {
            const s = getComputedStyle(e, "::-webkit-slider-thumb");
            return [parseFloat(s.width), parseFloat(s.height)]; }""")
        assert min(thumb) >= 24, thumb
        # The full view: every parameter, still nothing off-screen.
        page.click("#view-full")
        assert len(boxes(page, "input[type=range]")) == len(SPECS)
        assert_fits(page, PHONE["width"])
        assert_run_controls_on_screen(page, PHONE)
        # Words, with the paper's symbol beside them, and the explanation shown (no hover).
        label = page.inner_text("label[for=num-Slgt_R]")
        assert LABELS["Slgt_R"] in label and "Slgt_R" in label
        doc = page.locator("#range-Slgt_R ~ .doc")
        expect(doc).to_be_visible()
        assert SPECS["Slgt_R"].doc in doc.inner_text()
        page.click("#view-simple")
    finally:
        page.close()
    assert not errors, errors


def test_desktop_full_view(panel: tuple[PanelController, str], browser: Browser,
                           tmp_path: Path) -> None:
    _, base = panel
    page, errors = open_page(browser, base, DESKTOP)
    try:
        page.evaluate("localStorage.clear()")
        page.reload()
        page.wait_for_selector("#range-speed")
        expect(page.locator("body")).not_to_have_class(re.compile("simple"))
        assert len(boxes(page, "input[type=range]")) == len(SPECS)
        assert_fits(page, DESKTOP["width"])
        assert_run_controls_on_screen(page, DESKTOP)
        # Wide enough for the groups side by side, and the figures beside them.
        lefts = {round(b["x"]) for b in boxes(page, "fieldset")}
        assert len(lefts) >= 2, lefts
        side = boxes(page, "#side")[0]
        params = boxes(page, "#params")[0]
        assert side["x"] + side["w"] <= params["x"]
    finally:
        page.close()
    assert not errors, errors


def set_pad(page: Page, axes: list[float], *, buttons: tuple[int, ...] = ()) -> None:
    page.evaluate("""([axes, down]) => { window.__pad.axes = axes;
        window.__pad.buttons.forEach((b, i) => { b.pressed = down.includes(i);
                                                 b.value = b.pressed ? 1 : 0; });
        window.__pad.timestamp += 1; }""", [axes, list(buttons)])


def pad_event(page: Page, kind: str) -> None:
    page.evaluate("""kind => { window.__pads = kind === "gamepadconnected" ? [window.__pad] : [];
        if (kind !== "gamepadconnected") window.__pad.connected = false;
        const e = new Event(kind);
        Object.defineProperty(e, "gamepad", { value: window.__pad });
        window.dispatchEvent(e); }""", kind)


def test_gamepad_drives_and_its_disconnect_stops(panel: tuple[PanelController, str],
                                                browser: Browser) -> None:
    controller, base = panel
    page, errors = open_page(browser, base, PHONE, init=FAKE_PAD)
    try:
        controller.set_params({"speed": 0.5})
        pad_event(page, "gamepadconnected")
        expect(page.locator("#pad")).to_contain_text("Test pad")
        # The page ignores buttons held when the pad connects until it has polled them
        # released; its first poll also sends the centred sticks (speed 0): wait for that,
        # or a busy machine can put the press before the first poll and it is swallowed.
        assert wait_for(lambda: controller.params.speed == 0, 5.0), controller.params.speed
        set_pad(page, [0, 0, 0, 0], buttons=(0,))  # A: start
        assert wait_for(lambda: controller.running and controller.state()["state"]
                        == "walking", 10.0)
        set_pad(page, [0, 0, 0, 0])
        # Left stick fully forward, right stick half right: speed up to its maximum,
        # turn right (negative) by half its range; past the dead zone, scaled to the range.
        set_pad(page, [0.0, -1.0, 0.5 + 0.15 * 0.5, 0.0])
        hi, lo = SPECS["speed"].hi, SPECS["turn"].lo
        assert wait_for(lambda: abs(controller.params.speed - hi) < 1e-6
                        and abs(controller.params.turn - lo * 0.5) < 0.01, 5.0), \
            (controller.params.speed, controller.params.turn)
        assert wait_for(lambda: controller.live_params().speed == hi, 3.0)
        set_pad(page, [0.05, -0.1, 0.0, 0.0])  # inside the dead zone: centred
        assert wait_for(lambda: controller.params.speed == 0 and controller.params.turn == 0
                        and controller.params.side_step == 0, 5.0)
        set_pad(page, [0.0, -0.6, 0.0, 0.0])
        assert wait_for(lambda: controller.params.speed > 0.5, 5.0)
        pad_event(page, "gamepaddisconnected")
        expect(page.locator("#pad")).to_contain_text("disconnected")
        assert wait_for(lambda: not controller.running, 15.0), controller.state()["state"]
        assert controller.state()["state"] == "stopped"
        assert "panel stop" in (controller.last_stats.stop_reason if controller.last_stats
                                else "")
    finally:
        page.close()
        controller.set_params({"speed": 1.0, "turn": 0.0, "side_step": 0.0})
    assert not errors, errors


def test_keyboard_steers_stops_and_estops(panel: tuple[PanelController, str],
                                         browser: Browser) -> None:
    controller, base = panel
    page, errors = open_page(browser, base, DESKTOP)
    try:
        controller.set_params({"speed": 0.5, "turn": 0.0})
        controller.start()
        assert wait_for(lambda: controller.state()["state"] == "walking")
        # the page steps from the values the loop pushed: wait until it shows them
        expect(page.locator("#num-speed")).to_have_value("0.5")
        expect(page.locator("#num-turn")).to_have_value("0")
        page.locator("h1").click()
        page.keyboard.press("ArrowUp")
        assert wait_for(lambda: abs(controller.params.speed - 0.6) < 1e-9, 3.0), \
            controller.params.speed
        page.keyboard.press("a")
        assert wait_for(lambda: abs(controller.params.turn - 0.05) < 1e-9, 3.0)
        page.keyboard.press(" ")
        assert wait_for(lambda: not controller.running, 15.0)
        assert controller.state()["state"] == "stopped"
        controller.start()
        assert wait_for(lambda: controller.state()["state"] == "walking")
        page.keyboard.press("Escape")
        assert controller.wait(2.0) and controller.state()["state"] == "estop"
        assert not any(controller.state()["torque"])  # torque off
    finally:
        page.close()
        controller.set_params({"speed": 1.0, "turn": 0.0})
    assert not errors, errors


def test_every_parameter_has_a_label_in_words() -> None:
    assert set(LABELS) == set(SPECS)
    assert all(label and label != name for name, label in LABELS.items())
