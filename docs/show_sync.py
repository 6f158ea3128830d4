"""How closely the panel's page keeps a show's audio on the take's time: a 30 s show with a
soundtrack played from the panel in Debian's headless Chromium, the page's <audio> clock read
five times a second against the take's time on the robot (tests/show_sync.py). Prints the
worst, 90th percentile and median difference and the machine's load.

Run: ``MUJOCO_GL=egl .venv/bin/python docs/show_sync.py``
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
from playwright.sync_api import sync_playwright

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from panel_harness import ARGS, CHROMIUM, served_panel  # noqa: E402
from show_sync import AUTOPLAY, measure, write_show  # noqa: E402


def main() -> int:
    folder = Path(tempfile.mkdtemp())
    write_show(folder, seconds=33.0)
    with served_panel(studio_dir=folder) as (controller, base), sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=[*ARGS, AUTOPLAY])
        errors, span = measure(controller, base, browser, seconds=30.0)
        browser.close()
    held = np.abs(errors[5:])
    print(f"audio - take time over {span:.1f} s ({len(errors)} reads, the first second "
          f"left out): worst {held.max():.1f} ms, p90 {np.percentile(held, 90):.1f} ms, "
          f"median {np.median(held):.1f} ms, within 50 ms: {np.mean(held < 50):.0%}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    return 0 if held.max() < 50.0 else 1


if __name__ == "__main__":
    sys.exit(main())
