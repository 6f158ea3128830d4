"""Reply timeouts for the vendor SDKs talking to the pty emulator on a busy machine.

Both SDKs wait for a status packet ``2 * LATENCY_TIMER + 2`` ms plus its wire time
(``PortHandler.setPacketTimeout``), ``LATENCY_TIMER`` being a USB adapter's 16 ms latency
timer. The emulator is a child process sharing the CPUs with the test and whatever else
runs; with both cores of a CI machine busy it can wait longer than 34 ms for a turn, and
the SDK then reports a timeout for a reply that is on its way. The tests give the SDKs the
allowance of a slow adapter instead; a servo that does not answer still times out, later.
"""

from __future__ import annotations

import importlib

import pytest

#: Latency allowance [ms] while testing (a 16 ms allowance lost replies on a machine
#: with both cores busy; 100 ms still did now and then at a load average of 13).
TEST_LATENCY_MS = 200
#: How long the SDKs then wait for a status packet [s] (short packets; wire time ~0).
REPLY_WAIT_S = (2 * TEST_LATENCY_MS + 2) / 1000


def allow_slow_replies(monkeypatch: pytest.MonkeyPatch) -> None:
    """Raise both SDKs' latency timer to ``TEST_LATENCY_MS`` for one test."""
    for name in ("dynamixel_sdk.port_handler", "scservo_sdk.port_handler"):
        module = importlib.import_module(name)
        assert isinstance(module.LATENCY_TIMER, int)  # the SDK still has the seam
        monkeypatch.setattr(module, "LATENCY_TIMER", TEST_LATENCY_MS)
