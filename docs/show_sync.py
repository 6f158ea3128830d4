"""How closely the panel's page keeps a show's audio on the take's time: a 30 s show with a
soundtrack played from the panel in Debian's headless Chromium, the page's <audio> clock read
five times a second against the take's time on the robot (tests/show_sync.py). Prints the
first second's reads (the start) apart from the rest, the worst, 90th percentile and median
difference, how far the playback rate strayed from 1 (with the pitch kept off, that is the
pitch's change, in cents) and the machine's load. Exits 1 when a read is 50 ms or more off.

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
    every = np.abs(got.audio)
    first, held = every[:5], every[5:]
    guess = np.abs(got.estimate[5:])
    print(f"first second ({len(first)} reads): worst {first.max():.1f} ms, median "
          f"{np.median(first):.1f} ms; reads " + ", ".join(f"{a:+.0f}" for a in got.audio[:5]))
    print(f"after it, audio - take time over {got.span:.1f} s ({len(held)} reads): worst "
          f"{held.max():.1f} ms, p90 {np.percentile(held, 90):.1f} ms, median "
          f"{np.median(held):.1f} ms, within 50 ms: {np.mean(held < 50):.0%}; "
          f"the page's estimate of the take's time: worst {guess.max():.1f} ms, median "
          f"{np.median(guess):.1f} ms; {got.seeks[-1] if got.seeks else 0} seeks; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    cents = np.abs(1200 * np.log2(np.asarray(got.rate)))
    print(f"all {len(every)} reads: worst {every.max():.1f} ms, within 50 ms: "
          f"{np.mean(every < 50):.0%}; playback rate off 1 by (p95, worst) "
          f"{np.percentile(cents, 95):.0f}, {cents.max():.0f} cents")
    print("worst reads (t from the first [s], audio error, estimate error [ms]): " + ", ".join(
        f"{got.at[k] - got.at[0]:.1f} {got.audio[k]:+.0f} {got.estimate[k]:+.0f}"
        for k in sorted(np.argsort(-every)[:5])))
    return 0 if every.max() < 50.0 else 1

if __name__ == "__main__":
    sys.exit(main())
