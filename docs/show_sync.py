"""How closely the panel's page keeps a show's audio on the take's time: a 30 s show with a
soundtrack played from the panel in Debian's headless Chromium, the page's <audio> clock read
five times a second against the take's time on the robot (tests/show_sync.py). Prints the
worst, 90th percentile and median difference and the machine's load.

Run: ``MUJOCO_GL=egl .venv/bin/python docs/show_sync.py ['{"tau": 0.5}']`` (the optional JSON
object changes the page's follower settings, ``window.showTune`` in
robot/panel/static/studio.js)
"""

from __future__ import annotations

import json
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
        got = measure(controller, base, browser, seconds=30.0,
                      tune=json.loads(sys.argv[1]) if len(sys.argv) > 1 else None)
        browser.close()
    held = np.abs(got.audio[5:])
    guess = np.abs(got.estimate[5:])
    print(f"audio - take time over {got.span:.1f} s ({len(got.audio)} reads, the first "
          f"second left out): worst {held.max():.1f} ms, p90 {np.percentile(held, 90):.1f} "
          f"ms, median {np.median(held):.1f} ms, within 50 ms: {np.mean(held < 50):.0%}; "
          f"the page's estimate of the take's time: worst {guess.max():.1f} ms, median "
          f"{np.median(guess):.1f} ms; {got.seeks[-1] if got.seeks else 0} seeks; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    worst = int(np.argmax(held))
    print("worst reads (t from the first [s], audio error, estimate error [ms]): " + ", ".join(
        f"{got.at[5 + k] - got.at[0]:.1f} {got.audio[5 + k]:+.0f} {got.estimate[5 + k]:+.0f}"
        for k in sorted(np.argsort(-held)[:5])))
    return 0 if held[worst] < 50.0 else 1


if __name__ == "__main__":
    sys.exit(main())
