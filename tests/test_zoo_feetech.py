"""Feetech STS (little-endian) and SCS (big-endian) servos in one process.

feetech-servo-sdk keeps its byte order in a module-wide global (``scservo_def.SCS_END``,
set by ``PacketHandler(end)`` and ``SCS_SETEND``): any user of the SDK in the process can
flip it. The SDK's own ping converts the model number with it, so a flip under an STS
user makes 777 read 2307 (first test: the hazard, with the SDK alone). biped's Feetech bus
moves raw bytes and converts with its table's byte order, so two buses of the two series
stay right while a third party keeps flipping the global (second test).
"""

from __future__ import annotations

import random
import threading

import pytest
import scservo_sdk
from bus_harness import TEST_TIMEOUT_MS
from sdk_timeouts import allow_slow_replies

from robot.bus.feetech.bus import FeetechBus
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)
STS3215, SCS0009 = 777, 1284       # model numbers (robot/servo/models_feetech.py sources)


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


def test_the_sdks_own_ping_follows_the_global() -> None:
    with Emulator("feetech", ids=[1], model="STS3215") as emu:
        port = scservo_sdk.PortHandler(emu.port)
        assert port.openPort() and port.setBaudRate(1_000_000)
        try:
            ph = scservo_sdk.PacketHandler(0)
            assert ph.ping(port, 1)[:2] == (STS3215, scservo_sdk.COMM_SUCCESS)
            scservo_sdk.PacketHandler(1)       # another user of the SDK, an SCS one
            assert ph.ping(port, 1)[0] == 0x0903   # 777 = 0x0309 read the wrong way
        finally:
            scservo_sdk.SCS_SETEND(0)
            port.closePort()


def test_sts_and_scs_buses_stay_right_while_the_global_flips() -> None:
    with Emulator("feetech", ids=[1, 2], model="STS3215") as sts_emu, \
            Emulator("feetech", ids=[1, 2], model="SCS0009") as scs_emu:
        sts_emu.set_register(2, "present_position", 3000)
        scs_emu.set_register(2, "present_position", 700)
        sts = FeetechBus(sts_emu.port, baud=1_000_000, timeout_ms=TEST_TIMEOUT_MS,
                         check_health=False)
        scs = FeetechBus(scs_emu.port, baud=1_000_000, timeout_ms=TEST_TIMEOUT_MS,
                         check_health=False, family="feetech_scs")
        stop = threading.Event()
        seen: dict[str, list[tuple[int | None, int, int]]] = {"sts": [], "scs": []}
        errors: list[BaseException] = []

        def flip() -> None:
            rng = random.Random(1)
            while not stop.is_set():
                scservo_sdk.SCS_SETEND(rng.randint(0, 1))

        def poll(name: str, bus: FeetechBus) -> None:
            try:
                with bus:
                    for _ in range(25):
                        seen[name].append((bus.ping(1),
                                           bus.read_register(2, "present_position"),
                                           bus.read_register(1, "max_angle_limit")))
            except BaseException as e:      # reported below, not lost in the thread
                errors.append(e)

        threads = [threading.Thread(target=flip), threading.Thread(target=poll, args=(
            "sts", sts)), threading.Thread(target=poll, args=("scs", scs))]
        for t in threads:
            t.start()
        for t in threads[1:]:
            t.join(timeout=60)
        stop.set()
        threads[0].join()
        scservo_sdk.SCS_SETEND(0)
        assert not errors, errors
        assert set(seen["sts"]) == {(STS3215, 3000, 4095)}
        assert set(seen["scs"]) == {(SCS0009, 700, 1023)}
