"""`biped panel` ends safely whatever the signals: a subprocess on the pty emulator (both
protocols), end state read back from the emulated servos' registers."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from waiting import wait_for

import robot.cli as cli
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
Launch = Callable[..., "subprocess.Popen[str]"]
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}  # Goal Position, from the manuals
ONLY_PANEL = ("import sys, robot.cli as c; c.COMMANDS = ('panel',); "
              "sys.exit(c.main(sys.argv[1:]))")


@pytest.fixture
def panel_robot(tmp_path: Path, protocol: str) -> Path:
    """The bundled robot with a reply timeout for a busy test machine."""
    text = (ROBOTS_DIR / f"biped18-{protocol}.toml").read_text()
    path = tmp_path / "robot.toml"
    path.write_text(text.replace("timeout_ms = 20.0", "timeout_ms = 50.0"))
    return path


def state(url: str) -> str:
    with urllib.request.urlopen(url + "api/state", timeout=5) as r:
        return str(json.load(r)["state"])


@pytest.fixture
def launch(emu: Emulator, panel_robot: Path, tmp_path: Path) -> Iterator[Launch]:
    """``launch(*extra_args)`` → a walking `biped panel` process on the emulator."""
    procs: list[subprocess.Popen[str]] = []

    def start(*extra: str) -> subprocess.Popen[str]:
        cmd = [sys.executable, "-c", ONLY_PANEL, "panel", "--bus", emu.protocol, "--port",
               emu.port, "--robot", str(panel_robot), "--http-port", "0", "--rate", "50",
               "--presets-dir", str(tmp_path / "presets"), *extra]
        proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, env={**os.environ, "MUJOCO_GL": "egl"})
        procs.append(proc)
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert " open http://" in line, line + proc.stderr.read() if proc.stderr else ""
        url = line.split(" open ")[1].split()[0]
        deadline = time.monotonic() + 10
        while state(url) != "walking":
            assert time.monotonic() < deadline, "the panel never reached 'walking'"
            time.sleep(0.05)
        return proc

    yield start
    for p in procs:
        if p.poll() is None:
            p.kill()
            p.wait()


def finish(proc: subprocess.Popen[str]) -> tuple[int, str, str]:
    out, err = proc.communicate(timeout=20)
    return proc.returncode, out, err


def torque(emu: Emulator, robot: RobotConfig) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in robot.ids}


@pytest.mark.parametrize("second", [signal.SIGINT, signal.SIGTERM])
def test_second_signal_stops_at_once_torque_off(emu: Emulator, robot: RobotConfig,
                                                launch: Launch, second: int) -> None:
    proc = launch("--hold")
    assert proc.stderr is not None
    err_lines: list[str] = []
    reader = threading.Thread(target=lambda: err_lines.extend(iter(proc.stderr.readline, "")),
                              daemon=True)
    reader.start()
    proc.send_signal(signal.SIGINT)
    # The first is handled (the panel says so) before the second goes: two same-number
    # signals sent back to back may merge into one in the kernel.
    assert wait_for(lambda: any("stopping" in line for line in err_lines),
                    stop=lambda: proc.poll() is not None), "".join(err_lines)
    proc.send_signal(second)
    t0 = time.monotonic()
    out, _ = proc.communicate(timeout=20)
    reader.join(10)
    code, err = proc.returncode, "".join(err_lines)
    assert code == 130, err
    # Did not wait for the ramp-out: judged at the wire in ticks, not by the clock (a
    # loaded machine slows the exit): a few goals after the second signal (a ramp out
    # and the move to rest take dozens at 50 Hz), and the last goals are not rest.
    goals = [p for p in emu.log() if p.instruction == "sync_write"
             and p.address == GOAL_ADDRESS[emu.protocol]]
    assert len([p for p in goals if p.t > t0]) < 10, [p.t - t0 for p in goals if p.t > t0]
    sm = ServoMap(robot)
    assert goals[-1].values != sm.goals(sm.clamp(sm.vector(robot.rest)).tolist())
    assert "stopping" in out and "torque off" in out.splitlines()[-1], out
    assert "Traceback" not in err
    assert torque(emu, robot) == {0}


@pytest.mark.parametrize("hold", [True, False])
def test_one_signal_ramps_to_rest_then_holds_or_releases(emu: Emulator, robot: RobotConfig,
                                                         launch: Launch, hold: bool) -> None:
    extra = ["--set", "ramp_cycles=0.5"] + (["--hold"] if hold else [])
    proc = launch(*extra)
    proc.send_signal(signal.SIGINT if hold else signal.SIGTERM)
    code, out, err = finish(proc)
    assert code == (130 if hold else 143), err
    assert torque(emu, robot) == ({1} if hold else {0}), out + err
    sm = ServoMap(robot)
    rest = sm.goals(sm.clamp(sm.vector(robot.rest)).tolist())
    assert {i: emu.registers(i)["goal_position"] for i in robot.ids} == rest  # reached rest
    assert ("left ON" in out) == hold


def test_http_port_out_of_range_is_one_line_exit_2(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(cli, "COMMANDS", ("panel",))
    for bad in ("99999", "-1", "http"):
        assert cli.main(["panel", "--http-port", bad]) == 2
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1                                  # no usage block
        err = lines[0]
        assert err.endswith(f"argument --http-port: expected a port number in [0, 65535], "
                            f"got {bad!r}"), err
