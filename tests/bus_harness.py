"""Shared fixtures for the vendor-bus tests: a real SDK bus on an emulated chain (pty).

Use from a test module with ``pytest_plugins = ("bus_harness",)``.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType

import pytest

from robot.bus.factory import make_bus
from robot.bus.sdk.bus import SdkBus
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from sim.emulator.chain import Emulator

PROTOCOLS = ("dynamixel", "feetech")
HANG_LIMIT_S = 30
#: Reply timeout for tests [ms]: the emulator is a Python process on a shared machine (at a
#: load average of 10 on 2 cores it was measured stalling replies past 3 x 50 ms).
TEST_TIMEOUT_MS = 100.0
#: Reply timeout [ms] for tests in which no servo is made silent (so it costs nothing
#: there): at a load average of 10, and with the suite's workers beside two busy loops,
#: the starved emulator missed 3 x 100 ms (a hold's last read, a capture, a setup, a
#: ping). Tests that drop replies on purpose keep TEST_TIMEOUT_MS: their stops are timed.
PATIENT_TIMEOUT_MS = 250.0


def robot_for(protocol: str) -> RobotConfig:
    return load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")


def new_bus(emu: Emulator, robot: RobotConfig, **options: object) -> SdkBus:
    """A closed vendor bus on the emulator's pty, built by the factory like the CLI does."""
    options.setdefault("timeout_ms", TEST_TIMEOUT_MS)
    bus = make_bus(emu.protocol, robot=robot, port=emu.port, **options)
    assert isinstance(bus, SdkBus)
    return bus


def open_bus(emu: Emulator, robot: RobotConfig, **options: object) -> SdkBus:
    bus = new_bus(emu, robot, **options)
    bus.open()
    return bus


@pytest.fixture(autouse=True)
def no_hang(request: pytest.FixtureRequest) -> Iterator[None]:
    """Fail (rather than hang) any test of a module that uses this harness and runs
    longer than HANG_LIMIT_S. (A plugin's autouse fixture reaches every test of the
    session once one module loads it: tests of other modules are left alone.)"""
    if "bus_harness" not in getattr(request.module, "pytest_plugins", ()):
        yield
        return

    def alarm(signum: int, frame: FrameType | None) -> None:
        raise TimeoutError(f"test exceeded {HANG_LIMIT_S} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(HANG_LIMIT_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def bus_factory() -> Callable[..., SdkBus]:
    """``bus_factory(emu, robot, open=True, **options)`` → a vendor bus on the emulator."""
    def build(emu: Emulator, robot: RobotConfig, *, open: bool = True,
              **options: object) -> SdkBus:
        return open_bus(emu, robot, **options) if open else new_bus(emu, robot, **options)

    return build


@pytest.fixture(params=PROTOCOLS)
def protocol(request: pytest.FixtureRequest) -> str:
    return str(request.param)


@pytest.fixture
def robot(protocol: str) -> RobotConfig:
    return robot_for(protocol)


@pytest.fixture
def emu(protocol: str, robot: RobotConfig) -> Iterator[Emulator]:
    with Emulator(protocol, robot, seed=1) as e:
        yield e


@pytest.fixture
def bus(emu: Emulator, robot: RobotConfig) -> Iterator[SdkBus]:
    b = open_bus(emu, robot)
    yield b
    b.close()


@pytest.fixture
def robot_toml(tmp_path: Path, protocol: str, request: pytest.FixtureRequest) -> Path:
    """The bundled robot with a reply timeout that tolerates a busy test machine (the
    test module's ``REPLY_TIMEOUT_MS`` if it sets one, else ``TEST_TIMEOUT_MS``)."""
    timeout = getattr(request.module, "REPLY_TIMEOUT_MS", TEST_TIMEOUT_MS)
    return patient_copy(f"biped18-{protocol}", tmp_path / f"robot-{protocol}.toml",
                        timeout_ms=timeout)


def patient_copy(name: str, path: Path, *, timeout_ms: float = TEST_TIMEOUT_MS) -> Path:
    """The bundled robot ``name`` written to ``path`` with a reply timeout a busy test
    machine keeps (the bundled 20 ms is missed at load)."""
    text = (ROBOTS_DIR / f"{name}.toml").read_text()
    assert "timeout_ms = 20.0" in text, name
    path.write_text(text.replace("timeout_ms = 20.0", f"timeout_ms = {timeout_ms}"))
    return path
