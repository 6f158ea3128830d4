"""Screenshots of the panel for the README (docs/panel-phone.png, docs/panel.png): the
panel on the MuJoCo bus, walking, in Debian's headless Chromium at a phone's size
(390x844, the simple view) and a desktop's (1400x950, the full view).

Run: ``MUJOCO_GL=egl .venv/bin/python docs/make_panel_screenshots.py [OUT_DIR]``
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, LoopOptions, make_controller
from robot.panel.server import build_server, serve_in_thread
from robot.panel.studio import Studio

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu"]


def main(out: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0), preset="walk")
    tmp = Path(tempfile.mkdtemp())
    server = build_server(controller, port=0, studio=Studio(
        controller, takes_dir=tmp / "takes", keys_dir=tmp / "keys"))
    _, base = serve_in_thread(server)
    controller.start()
    time.sleep(2.5)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            for name, size, view in (("panel-phone.png", (390, 844), "simple"),
                                     ("panel.png", (1400, 950), "full")):
                page = browser.new_page(viewport={"width": size[0], "height": size[1]},
                                        device_scale_factor=1)
                page.goto(base)
                page.wait_for_selector("#range-speed", state="attached")
                page.click(f"#view-{view}")
                time.sleep(1.0)
                page.screenshot(path=str(out / name))
                page.close()
            browser.close()
    finally:
        server.shutdown()
        server.server_close()
        controller.emergency_stop()
        controller.shutdown()


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent)
