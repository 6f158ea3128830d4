"""Issue 19 (items 4, 5, 8): the end paths of every command that drives servos besides
`walk` (tests/test_fault_matrix.py): `pose`, `play`, `capture`, `calibrate`, `monitor`,
`setup-motors`, `torque`, each as a real `biped` process on the pty emulator, with SIGINT,
SIGTERM, two signals 5-300 ms apart, bus faults and a full disk.

Judged at the wire (torque per servo, the Bus Watchdog register of Dynamixel X) and by the
exit code: 0 done, 1 safety stop or incomplete, 2 bad input, 128 + the first signal, never
killed by the signal (a negative return code). What a command says it left the servos
doing must be what the registers show. Signals are sent once the process has said it
reached the state the test needs (a prompt, a table, goals on the wire), never after a
fixed sleep; the gap between two signals is the variable under test.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from bus_harness import PATIENT_TIMEOUT_MS, patient_copy
from test_fault_matrix import goal_writes, rest_ticks, tick_window
from test_keyframes import WAVE
from waiting import sleep_until, wait_for

from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness", "full_disk")

REPO = Path(__file__).resolve().parent.parent
GAPS_MS = (5, 50, 150, 300)
TWICE = {"sigint": (signal.SIGINT, signal.SIGINT), "sigterm": (signal.SIGTERM, signal.SIGTERM)}


class Biped:
    """A `biped` process (``python -m robot.cli``, as the console script runs it) whose
    stdout and stderr are read as they come, a prompt without its newline included."""

    def __init__(self, *argv: str, stdin: bool = False) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "robot.cli", *argv], cwd=REPO, text=True,
            stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            env={**os.environ, "MUJOCO_GL": "egl"})
        self.out: list[str] = []
        self.err: list[str] = []
        self._readers = [threading.Thread(target=self._read, args=(s, lines), daemon=True)
                         for s, lines in ((self.proc.stdout, self.out),
                                          (self.proc.stderr, self.err))]
        for r in self._readers:
            r.start()

    @staticmethod
    def _read(stream: object, lines: list[str]) -> None:
        """Character by character: the last item grows until its newline."""
        lines.append("")
        for ch in iter(lambda: stream.read(1), ""):  # type: ignore[attr-defined]
            lines[-1] += ch
            if ch == "\n":
                lines.append("")

    def running(self) -> bool:
        return self.proc.poll() is None

    def said(self, text: str, *, where: str = "out") -> None:
        """Wait until a line containing ``text`` is printed (stdout or stderr)."""
        lines = self.out if where == "out" else self.err
        assert wait_for(lambda: any(text in line for line in lines),
                        stop=lambda: not self.running()), self.text()

    def when(self, cond: object) -> None:
        assert wait_for(cond, stop=lambda: not self.running()), self.text()  # type: ignore[arg-type]

    def signals(self, sent: tuple[int, ...], *, gap_ms: float = 50.0) -> None:
        """The first signal; once the process said it is stopping, the others ``gap_ms``
        later (two same-number signals sent back to back may merge in the kernel)."""
        for k, sig in enumerate(sent):
            if k:
                self.said("stopping", where="err")
                sleep_until(time.monotonic() + gap_ms / 1e3)
            if self.running():
                self.proc.send_signal(sig)

    def send(self, text: str) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(text)
        self.proc.stdin.flush()

    def finish(self, timeout: float = 30.0) -> tuple[int, str, str]:
        try:
            self.proc.wait(timeout)
        finally:
            if self.running():
                self.proc.kill()
                self.proc.wait()
        for r in self._readers:
            r.join(10)
        code, out, err = self.proc.returncode, "".join(self.out), "".join(self.err)
        assert code >= 0, f"killed by signal {-code}: {out}{err}"
        assert "Traceback" not in err, err
        return code, out, err

    def text(self) -> str:
        return "".join(self.out) + "".join(self.err)


#: Reply timeout of these tests' robot file [ms] (bus_harness's robot_toml): each test runs
#: a whole `biped` process beside its emulator (the harness's 100 ms was missed three
#: times in a row at load: a failed arm of the Bus Watchdog, exit 1).
REPLY_TIMEOUT_MS = PATIENT_TIMEOUT_MS


def bus_args(emu: Emulator, robot_toml: Path) -> list[str]:
    return ["--bus", emu.protocol, "--port", emu.port, "--robot", str(robot_toml)]


def torque(emu: Emulator, robot: RobotConfig) -> set[int]:
    return {emu.registers(i)["torque_enable"] for i in robot.ids}


def watchdog(emu: Emulator, robot: RobotConfig) -> set[int]:
    """Dynamixel X Bus Watchdog (98) of every servo: 0 disarmed, -1 tripped, >0 armed;
    {0} for a Feetech, which has none."""
    return {emu.registers(i).get("bus_watchdog", 0) for i in robot.ids}


def goals_sent(emu: Emulator) -> int:
    return emu.counters().get("sync_write", 0)


def assert_goals_safe(emu: Emulator, robot: RobotConfig, rate_hz: float) -> None:
    """Every goal on the wire inside the joint limits, consecutive goals within the slew
    limit at ``rate_hz`` (the manual's tick formula, tests/test_fault_matrix.py)."""
    goals = goal_writes(emu)
    assert goals, "no goal reached the servos"
    ticks = np.array([[p.values[i] for i in robot.ids] for p in goals])
    window = tick_window(robot)
    assert all(window[i][0] <= t <= window[i][1] for row in ticks
               for i, t in zip(robot.ids, row, strict=True)), "a goal left the joint limits"
    step = np.array([j.max_speed_rad_s / rate_hz * 4096 / (2 * math.pi) for j in robot.joints])
    assert (np.abs(np.diff(ticks, axis=0)) <= step + 1.0).all(), "a goal broke the slew limit"


def assert_released(emu: Emulator, robot: RobotConfig) -> None:
    """Torque off on every servo and no Bus Watchdog left armed or tripped."""
    assert torque(emu, robot) == {0}
    assert watchdog(emu, robot) == {0}


# ------------------------------------------------------------------------------ pose
@pytest.mark.parametrize("gap_ms", GAPS_MS)
@pytest.mark.parametrize("twice", sorted(TWICE))
@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_pose_two_signals(emu: Emulator, robot: RobotConfig, robot_toml: Path, twice: str,
                          gap_ms: int) -> None:
    """Item 4: the first signal stops the ramp and holds; a second one that reaches the
    command before it has left the servos turns torque off. Whenever it lands, the exit
    code is 128 + the first and the last line says what the registers show."""
    sent = TWICE[twice]
    p = Biped("pose", "rest", *bus_args(emu, robot_toml), "--rate", "50", "--speed", "0.2")
    p.when(lambda: goals_sent(emu) >= 20)                 # ramping (a 10 s move)
    p.signals(sent, gap_ms=gap_ms)
    code, out, err = p.finish()
    assert code == 128 + sent[0], err
    assert_goals_safe(emu, robot, 50.0)
    last = out.splitlines()[-1]
    assert watchdog(emu, robot) == {0}                     # never left armed or tripped
    if "second signal" in last or " again: " in err:       # it heard the second: off
        assert "torque off" in last and torque(emu, robot) == {0}, out + err
    else:                                                  # it had ended first: holding
        assert "torque stays ON" in last and torque(emu, robot) == {1}, out + err


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize("protocol", ["feetech"])
def test_pose_one_signal_holds(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                               sig: int) -> None:
    p = Biped("pose", "rest", *bus_args(emu, robot_toml), "--rate", "50", "--speed", "0.2")
    p.when(lambda: goals_sent(emu) >= 20)
    p.signals((sig,))
    code, out, err = p.finish()
    assert code == 128 + sig, err
    assert "torque stays ON" in out.splitlines()[-1]
    assert torque(emu, robot) == {1}


def knee_progress(emu: Emulator, robot: RobotConfig) -> float:
    """How far the right knee's last goal is from its zero (where the emulator starts it)
    to its rest angle (the robot file's [rest], through the manual's tick formula)."""
    j = robot.joint("r_knee")
    rest = j.zero_ticks + j.sign * robot.rest["r_knee"] * 4096 / (2 * math.pi)
    return (emu.registers(j.servo_id)["goal_position"] - j.zero_ticks) / (rest - j.zero_ticks)


def test_pose_with_every_reply_dropped_ends_torque_off(
        emu: Emulator, robot: RobotConfig, robot_toml: Path) -> None:
    """Item 8: the servos stop answering near the end of the ramp, so fewer than five
    read-backs fail before it is done: the pose ended "torque left ON", exit 0. A fault
    ends with torque off, and a hold needs servos that answer."""
    p = Biped("pose", "rest", *bus_args(emu, robot_toml), "--rate", "50", "--speed", "0.5")
    # 1.1 rad at a peak 0.5 rad/s: a 4.1 s minimum-jerk ramp; 95 % of the way is at 78 %
    # of its time: 0.9 s (four read-backs at 50 Hz / 10) are left.
    p.when(lambda: knee_progress(emu, robot) >= 0.95)
    emu.set_faults(drop_rate=1.0)
    code, out, err = p.finish()
    emu.clear_faults()
    assert code == 1, out + err
    last = out.splitlines()[-1]
    assert last.startswith("stopped: watchdog") and "torque ON" not in last, last
    assert torque(emu, robot) == {0}                       # the torque-off packet needs no reply


# ------------------------------------------------------------------------------ bus faults
FAULTS = {  # name: what the emulator does to the right knee (or to every reply)
    "every reply dropped": lambda emu, knee: emu.set_faults(drop_rate=1.0),
    "a silent servo": lambda emu, knee: emu.set_faults(vanish={knee: 0.0}),
    "overload flag": lambda emu, knee: emu.set_faults(hw_error={knee: "overload"}),
}


def run_with_fault(p: Biped, emu: Emulator, robot: RobotConfig, fault: str
                   ) -> tuple[int, str, str, tuple[int, ...]]:
    """Inject ``fault`` once goals flow; the exit, outputs and the servos that can still
    hear a packet (a silent one cannot, by definition)."""
    knee = robot.joint("r_knee").servo_id
    p.when(lambda: goals_sent(emu) >= 20)
    FAULTS[fault](emu, knee)
    code, out, err = p.finish()
    emu.clear_faults()
    return code, out, err, tuple(i for i in robot.ids if fault != "a silent servo" or i != knee)


@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_pose_bus_fault_mid_ramp(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                 fault: str) -> None:
    """A fault mid-ramp: a safety stop, exit 1, torque off on every servo that hears."""
    p = Biped("pose", "rest", *bus_args(emu, robot_toml), "--rate", "50", "--speed", "0.2")
    code, out, err, reachable = run_with_fault(p, emu, robot, fault)
    assert code == 1, out + err
    assert_goals_safe(emu, robot, 50.0)
    last = out.splitlines()[-1]
    assert last.startswith("stopped: watchdog") and "torque ON" not in last, last
    assert {emu.registers(i)["torque_enable"] for i in reachable} == {0}


@pytest.mark.parametrize("fault", sorted(FAULTS))
@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_play_bus_fault(emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
                        fault: str) -> None:
    seq = tmp_path / "wave.toml"
    seq.write_text(WAVE)
    p = Biped("play", str(seq), *bus_args(emu, robot_toml), "--seconds", "60", "--json")
    code, out, err, reachable = run_with_fault(p, emu, robot, fault)
    assert code == 1, out + err
    result = json.loads(out)
    assert result["fault"] and result["stop_reason"].startswith("watchdog")
    assert result["torque"] in ("off", "sent") and not result["holding"]
    assert {emu.registers(i)["torque_enable"] for i in reachable} == {0}


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_calibrate_servo_goes_silent_at_a_prompt(emu: Emulator, robot: RobotConfig,
                                                 robot_toml: Path, tmp_path: Path) -> None:
    out_file = tmp_path / "calibrated.toml"
    p = Biped("calibrate", *bus_args(emu, robot_toml), "--out", str(out_file), stdin=True)
    p.said("torque OFF on")
    emu.set_faults(vanish={robot.joint("r_knee").servo_id: 0.0})
    p.send("\n")                                          # step 1 reads every servo
    code, out, err = p.finish()
    emu.clear_faults()
    assert code == 1, out + err
    assert "bus error" in err and "(r_knee)" in err and not out_file.exists()
    assert torque(emu, robot) == {0}


# ------------------------------------------------------------------------------ capture
@pytest.mark.parametrize("sent", [(signal.SIGTERM,), (signal.SIGINT,),
                                  (signal.SIGTERM, signal.SIGTERM),
                                  (signal.SIGINT, signal.SIGTERM)],
                         ids=["sigterm", "sigint", "sigterm_twice", "sigint_sigterm"])
def test_capture_signals_leave_every_servo_limp(emu: Emulator, robot: RobotConfig,
                                                robot_toml: Path, tmp_path: Path,
                                                sent: tuple[int, ...]) -> None:
    """Item 5: SIGTERM while the arms are released (the legs hold, watchdog disarmed)
    killed capture (-15) with servos 1-12 torqued. Any signal: torque off everywhere,
    nothing written, 128 + the first signal."""
    out_file = tmp_path / "keys.toml"
    p = Biped("capture", *bus_args(emu, robot_toml), "--limb", "arms", "--out",
              str(out_file), stdin=True)
    p.said("Move it by hand")
    assert torque(emu, robot) == {0, 1}                    # legs hold, arms limp
    p.signals(sent)
    code, out, err = p.finish()
    assert code == 128 + sent[0], err
    assert_released(emu, robot)
    assert not out_file.exists()
    assert "torque OFF on every servo" in out.splitlines()[-1]


def test_capture_bus_fault_at_a_keyframe(emu: Emulator, robot: RobotConfig,
                                         robot_toml: Path, tmp_path: Path) -> None:
    """The servos stop answering while posing: Enter reads them, fails: exit 1 (a
    hardware fault, not bad input), one line, torque off (the packet needs no reply)."""
    out_file = tmp_path / "keys.toml"
    p = Biped("capture", *bus_args(emu, robot_toml), "--limb", "arms", "--out",
              str(out_file), stdin=True)
    p.said("Move it by hand")
    emu.set_faults(drop_rate=1.0)
    p.send("\n")
    code, out, err = p.finish()
    emu.clear_faults()
    assert code == 1, out + err
    assert [line for line in err.splitlines() if line.startswith("biped capture:")]
    assert torque(emu, robot) == {0}
    assert not out_file.exists()


# ------------------------------------------------------------------------------ calibrate
@pytest.mark.parametrize("sent", [(signal.SIGTERM,), (signal.SIGINT, signal.SIGINT)],
                         ids=["sigterm", "sigint_twice"])
def test_calibrate_signal_at_a_prompt(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                      tmp_path: Path, sent: tuple[int, ...]) -> None:
    out_file = tmp_path / "calibrated.toml"
    p = Biped("calibrate", *bus_args(emu, robot_toml), "--out", str(out_file), stdin=True)
    p.said("torque OFF on")
    p.signals(sent)
    code, out, err = p.finish()
    assert code == 128 + sent[0], err
    assert_released(emu, robot)
    assert not out_file.exists()


# ------------------------------------------------------------------------------ monitor
@pytest.mark.parametrize("sent", [(signal.SIGTERM,), (signal.SIGTERM, signal.SIGINT)],
                         ids=["sigterm", "sigterm_sigint"])
def test_monitor_signals(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                         sent: tuple[int, ...]) -> None:
    p = Biped("monitor", *bus_args(emu, robot_toml), "--json", "--rate", "20")
    p.when(lambda: any(line.startswith("{") for line in p.out))
    emu.set_faults(drop_rate=1.0)                          # a failed read is a line; it goes on
    p.when(lambda: any('"error"' in line for line in p.out))
    emu.clear_faults()
    p.signals(sent)
    code, out, err = p.finish()
    assert code == 128 + sent[0], err
    assert torque(emu, robot) == {0}
    assert all(json.loads(line) for line in out.splitlines())


# ------------------------------------------------------------------------------ torque
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_torque_on_interrupted(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                               sig: int) -> None:
    """`torque on` streams a 0.3 s move to where the servos are, then holds. A signal while
    it streams: torque off, 128 + signal; one that comes after it has finished: exit 0,
    holding (what it printed). Never killed."""
    p = Biped("torque", "on", *bus_args(emu, robot_toml))
    p.when(lambda: goals_sent(emu) >= 2)
    p.signals((sig,))
    code, out, err = p.finish()
    if code == 0:
        assert "torque ON" in out and torque(emu, robot) == {1}
    else:
        assert code == 128 + sig, out + err
        assert_released(emu, robot)


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_servo_missing_at_start_is_a_hardware_fault(emu: Emulator, robot: RobotConfig,
                                                    robot_toml: Path) -> None:
    """Item 11: a servo that does not answer is a hardware fault (exit 1), not bad input
    (2); one line naming it; nothing written."""
    knee = robot.joint("l_knee").servo_id
    emu.set_faults(missing_ids=[knee])
    emu.log(clear=True)
    p = Biped("torque", "on", *bus_args(emu, robot_toml))
    code, out, err = p.finish()
    assert code == 1, out + err
    lines = [line for line in err.splitlines() if line.startswith("biped torque")]
    assert len(lines) == 1 and f"id {knee} (l_knee)" in lines[0], err
    writes = [q for q in emu.log() if q.instruction in ("write", "sync_write")]
    assert writes == [] and torque(emu, robot) == {0}


# ------------------------------------------------------------------------------ play
@pytest.mark.parametrize("sent", [(signal.SIGTERM,), (signal.SIGTERM, signal.SIGTERM)],
                         ids=["sigterm", "sigterm_twice"])
@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_play_signals(emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
                      sent: tuple[int, ...]) -> None:
    seq = tmp_path / "wave.toml"
    seq.write_text(WAVE)
    p = Biped("play", str(seq), *bus_args(emu, robot_toml), "--seconds", "60", "--json")
    p.when(lambda: goals_sent(emu) >= 100)
    p.signals(sent)
    code, out, err = p.finish()
    assert code == 128 + sent[0], err
    result = json.loads(out)
    assert result["torque"] == "off" and not result["holding"]
    assert_released(emu, robot)
    assert_goals_safe(emu, robot, 200.0)
    if len(sent) == 1:                                     # a stop, not an e-stop: at rest
        assert {i: emu.registers(i)["goal_position"] for i in robot.ids} == rest_ticks(robot)


# ------------------------------------------------------------------------------ setup-motors
@pytest.mark.parametrize("sent", [(signal.SIGTERM,), (signal.SIGINT, signal.SIGINT)],
                         ids=["sigterm", "sigint_twice"])
def test_setup_motors_signal_at_the_prompt(robot_toml: Path, protocol: str,
                                           sent: tuple[int, ...]) -> None:
    with Emulator.factory_new(protocol, 1) as emu:
        emu.plug(0)
        before = emu.registers_of(0)
        p = Biped("setup-motors", "--robot", str(robot_toml), "--port", emu.port, stdin=True)
        p.said("connect only the servo")
        p.signals(sent)
        code, out, err = p.finish()
        assert code == 128 + sent[0], err
        after = emu.registers_of(0)
        assert (after["id"], after["baud_rate"]) == (before["id"], before["baud_rate"])


# ------------------------------------------------------------------------------ full disk
@pytest.mark.parametrize("cmd", ["capture --out", "calibrate --out", "play --record"])
def test_output_on_a_full_disk_is_refused_before_the_port(emu: Emulator, robot_toml: Path,
                                                          full_dir: Path, tmp_path: Path,
                                                          cmd: str) -> None:
    emu.log(clear=True)
    name, option = cmd.split()
    seq = tmp_path / "wave.toml"
    seq.write_text(WAVE)
    argv = [name, *([str(seq)] if name == "play" else []), *bus_args(emu, robot_toml),
            option, str(full_dir / ("x.csv" if name == "play" else "x.toml"))]
    p = Biped(*argv, stdin=True)
    code, out, err = p.finish()
    assert code == 2, out + err
    assert len(err.strip().splitlines()) == 1 and option in err and "space" in err, err
    assert emu.log() == []                                  # the port was not used


# ------------------------------------------------------------------------------ scan
AX_LOCK, AX_RETURN_DELAY = 47, 5            # AX-12A control table (ROBOTIS e-Manual)


def test_fix_return_delay_never_locks_an_ax12_eeprom(tmp_path: Path) -> None:
    """Item 9: on AX-12As `scan --fix-return-delay` wrote Lock (47) = 1, which locks their
    EEPROM until power-off (the Feetech unlock/relock dance applied to the wrong family).
    Only Return Delay Time (5) may be written, and only where it is not 0 already."""
    import robot.cli as cli

    ax12 = patient_copy("biped18-ax12", tmp_path / "biped18-ax12.toml")
    with Emulator("dynamixel1", load_robot(ax12)) as emu:
        for sid in (3, 7):
            emu.set_register(sid, "return_delay_time", 250)
        emu.log(clear=True)
        assert cli.main(["scan", "--bus", "dynamixel1", "--port", emu.port, "--robot",
                         str(ax12), "--ids", "1-18", "--fix-return-delay", "--json"]) == 0
        writes = [p for p in emu.log() if p.instruction in ("write", "sync_write", "reg_write")]
        assert AX_LOCK not in {p.address for p in writes}
        assert sorted((p.address, sid) for p in writes if p.address == AX_RETURN_DELAY
                      for sid in p.values) == [(AX_RETURN_DELAY, 3), (AX_RETURN_DELAY, 7)]
        assert {emu.registers(i)["lock"] for i in range(1, 19)} == {0}
        assert {emu.registers(i)["return_delay_time"] for i in range(1, 19)} == {0}
