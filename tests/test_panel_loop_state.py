"""A frozen loop process as the panel's web side meets it: every caller is told at once,
and the loop is asked once, not once per caller (robot.panel.loop_state). A live frame
reads the state several times; before, each read waited out the whole timeout."""

from __future__ import annotations

import os
import re
import signal

from panel_harness import served_panel
from waiting import wait_for

from robot.panel.controller import PanelController


def _silent_s(controller: PanelController) -> float:
    s = controller.state()
    assert s["state"] == "fault" and not s["running"], s
    m = re.fullmatch(r"the control loop did not answer for (\d+\.\d) s", s["fault"] or "")
    assert m, s["fault"]
    return float(m.group(1))


def test_a_frozen_loop_is_asked_once_and_every_caller_told() -> None:
    with served_panel() as (controller, _):
        controller.start()
        assert wait_for(lambda: controller.state()["state"] == "walking")
        loop = controller.pid
        assert loop is not None
        os.kill(loop, signal.SIGSTOP)
        try:
            # an answer already on its way when the signal came may still be read
            assert wait_for(lambda: controller.state()["state"] == "fault")
            silences = [_silent_s(controller)]
            for _ in range(5):                 # a frame's reads: state, params, driver
                assert controller.live_params().as_dict() and controller.loop_rate_hz() >= 0
                silences.append(_silent_s(controller))
            assert controller.loop.in_flight("state") == 1        # one question, unanswered
            assert silences == sorted(silences)                   # silent ever longer
        finally:
            os.kill(loop, signal.SIGCONT)
        assert wait_for(lambda: controller.state()["state"] == "walking")
        assert controller.state()["fault"] is None
        assert controller.loop.in_flight("state") == 0
