"""Every way `biped panel` ends, at the wire: a subprocess on the pty emulator (the real
SDK), walking, idle, recording or with a limb released, stopped by SIGINT, SIGTERM, or two
of them 5-300 ms apart; a bus that dies under it; a full disk under its record and save
routes. Judged by the exit code (128 + the first signal, never killed by a signal, 1 when
torque could not be confirmed off), the emulator's registers (torque per servo, the Bus
Watchdog) and the last line, which must say what the wire was told."""

from __future__ import annotations

import math
import os
import signal
import time
from pathlib import Path

import pytest
from panel_wire import Panel, children, gone, launched, torque_now
from waiting import sleep_until, wait_for

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

INT, TERM = signal.SIGINT, signal.SIGTERM
RESOLUTION = 4096  # ticks per turn (XL430)
RATE = 100.0  # [Hz]: what matters here is how it ends, not how fast it runs


@pytest.fixture
def protocol() -> str:
    return "dynamixel"  # the Bus Watchdog shows a stalled or unreachable loop


def rest_goals(robot: RobotConfig) -> list[int]:
    """The rest pose in ticks, by the manual's formula (ticks = zero + sign q 4096/2pi)."""
    out = []
    for j in robot.joints:
        q = min(max(robot.rest.get(j.name, 0.0), j.min_rad), j.max_rad)
        out.append(round(j.zero_ticks + j.sign * q * RESOLUTION / (2 * math.pi)))
    return out


def walking(panel: Panel) -> None:
    assert wait_for(lambda: panel.state()["state"] == "walking"), panel.state()


def end(panel: Panel) -> tuple[int, str]:
    out, _ = panel.proc.communicate(timeout=25)
    return panel.proc.returncode, out


def signals(panel: Panel, sent: tuple[int, ...], gap_s: float) -> None:
    t0 = time.monotonic()
    for k, sig in enumerate(sent):
        sleep_until(t0 + k * gap_s)
        panel.proc.send_signal(sig)


@pytest.mark.parametrize(("pair", "gap_ms"), [
    ((INT, INT), 5), ((INT, INT), 50), ((INT, INT), 100), ((INT, INT), 300),
    ((TERM, TERM), 5), ((TERM, TERM), 300), ((TERM, INT), 100)])
def test_two_signals_while_walking(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                   tmp_path: Path, pair: tuple[int, int], gap_ms: int) -> None:
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        signals(panel, pair, gap_ms / 1000)
        code, out = end(panel)
    err = "".join(panel.err)
    assert code == 128 + pair[0], (code, out, err)
    assert out.splitlines()[-1] == "biped panel: stopped; torque off", out
    assert set(torque_now(emu, robot).values()) == {0}
    assert "Traceback" not in err


@pytest.mark.parametrize(("sent", "gap_ms"), [((TERM,), 0), ((INT, INT), 5),
                                              ((TERM, TERM), 100)])
def test_signals_while_idle(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                            tmp_path: Path, sent: tuple[int, ...], gap_ms: int) -> None:
    """Nothing running: the panel closes at once, so a second signal may come while the
    process is already ending; it is recorded, never the default action."""
    with launched(emu, robot_toml, tmp_path, rate=RATE) as panel:
        assert panel.state()["state"] == "idle"
        signals(panel, sent, gap_ms / 1000)
        code, out = end(panel)
    assert code == 128 + sent[0], (code, out, "".join(panel.err))
    assert out.splitlines()[-1] == "biped panel: stopped; torque off", out
    assert set(torque_now(emu, robot).values()) == {0}


@pytest.mark.parametrize("sig", [INT, TERM])
def test_signal_with_a_limb_released_or_recording(emu: Emulator, robot: RobotConfig,
                                                  robot_toml: Path, tmp_path: Path,
                                                  sig: int) -> None:
    """A released limb leaves the others holding torque (no run): a signal still ends
    with torque off everywhere. A recording ends its take (the stop is in it)."""
    with launched(emu, robot_toml, tmp_path, rate=RATE) as panel:
        assert panel.request("POST", "/api/pose/release", {"limb": "arms"})[0] == 200
        arms = {robot.joint(j).servo_id for j in robot.joint_names if "shoulder" in j
                or "elbow" in j}
        held = {i: v for i, v in torque_now(emu, robot).items() if i not in arms}
        assert set(held.values()) == {1}                        # the legs hold
        panel.proc.send_signal(sig)
        code, out = end(panel)
    assert code == 128 + sig and out.splitlines()[-1].endswith("torque off"), out
    assert set(torque_now(emu, robot).values()) == {0}
    with launched(emu, robot_toml, tmp_path, rate=RATE) as panel:
        assert panel.request("POST", "/api/record", {"name": "sig"})[0] == 200
        walking(panel)
        panel.proc.send_signal(sig)
        code, out = end(panel)
    assert code == 128 + sig, out
    assert set(torque_now(emu, robot).values()) == {0}
    take = (tmp_path / "studio" / "takes" / "sig.take.jsonl").read_text().splitlines()
    assert any('"stop": true' in line for line in take) and '"rest"' in take[-1]


def test_bus_dies_under_the_panel(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                  tmp_path: Path) -> None:
    """The adapter vanishes mid-walk: the run stops on the watchdog, the panel says so
    and keeps serving; at the end it does not claim torque off (it could not be sent):
    exit 1, and the servos' own watchdog has stopped them where they are."""
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        emu.set_faults(close_port=True)
        assert wait_for(lambda: not panel.state()["running"]), panel.state()
        s = panel.state()
        assert s["fault"] and "bus errors" in s["fault"], s
        panel.proc.send_signal(TERM)
        code, out = end(panel)
    last = out.splitlines()[-1]
    assert code == 1, out
    assert "torque NOT confirmed off" in last and not last.endswith("torque off"), last
    assert wait_for(lambda: {emu.registers(i)["bus_watchdog"] for i in robot.ids} == {-1})
    regs = [emu.registers(i) for i in robot.ids]                # tripped: stopped
    assert {r["torque_enable"] for r in regs} == {1}            # unreachable: still on


def test_full_disk_under_record_and_save(emu: Emulator, robot: RobotConfig, robot_toml: Path,
                                         tmp_path: Path) -> None:
    """The take cannot be written: the run ends as a fault (ramp out, torque off) and the
    panel shows why; a sequence that cannot be saved is one 400 line; the panel serves
    on and ends cleanly."""
    takes, keys = tmp_path / "studio" / "takes", tmp_path / "studio" / "keyframes"
    takes.mkdir(parents=True)
    keys.mkdir(parents=True)
    (takes / "full.take.jsonl").symlink_to("/dev/full")
    (keys / "full.toml").symlink_to("/dev/full")
    with launched(emu, robot_toml, tmp_path, rate=RATE) as panel:
        assert panel.request("POST", "/api/record", {"name": "full"})[0] == 200
        assert wait_for(lambda: not panel.state()["running"]), panel.state()
        s = panel.state()
        assert s["fault"] and "No space left on device" in s["fault"], s
        assert set(torque_now(emu, robot).values()) == {0}
        assert panel.request("POST", "/api/pose/release", {"limb": "arms"})[0] == 200
        assert panel.request("POST", "/api/pose/capture", {})[0] == 200
        status, reply = panel.request("POST", "/api/pose/save", {"name": "full"})
        assert status == 400 and "No space left on device" in reply["error"], reply
        assert "\n" not in reply["error"]
        panel.proc.send_signal(INT)
        code, out = end(panel)
    assert code == 130 and out.splitlines()[-1].endswith("torque off"), out
    assert set(torque_now(emu, robot).values()) == {0}
    assert os.path.islink(takes / "full.take.jsonl")


def test_a_refused_record_keeps_the_take_of_that_name(emu: Emulator, robot: RobotConfig,
                                                     robot_toml: Path, tmp_path: Path) -> None:
    """Issue 36: a recording that never starts (a joint outside its limits) leaves the take
    already under that name as it was; the panel says why and serves on."""
    takes = tmp_path / "studio" / "takes"
    takes.mkdir(parents=True)
    old = takes / "keep.take.jsonl"
    old.write_text('{"take": 1}\n{"tick": 1}\n')
    knee = robot.joint("r_knee")
    beyond = knee.max_rad + 0.3
    emu.set_register(knee.servo_id, "present_position", round(
        knee.zero_ticks + knee.sign * beyond * RESOLUTION / (2 * math.pi)))
    with launched(emu, robot_toml, tmp_path, rate=RATE) as panel:
        panel.request("POST", "/api/record", {"name": "keep"})
        assert wait_for(lambda: not panel.state()["running"]
                        and "refusing to start" in str(panel.state())), panel.state()
        panel.proc.send_signal(TERM)
        code, out = end(panel)
    assert code == 128 + TERM, out
    assert old.read_text() == '{"take": 1}\n{"tick": 1}\n'
    assert sorted(p.name for p in takes.iterdir()) == ["keep.take.jsonl"]


def test_web_side_killed_the_loop_stops_the_robot(emu: Emulator, robot: RobotConfig,
                                                  robot_toml: Path, tmp_path: Path) -> None:
    """SIGKILL on `biped panel` (nothing of it runs any more): its loop process sees the
    pipe end, ramps out, rests, turns torque off and exits."""
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        (loop,) = children(panel.proc.pid)
        panel.proc.kill()
        panel.proc.wait(10)
        assert wait_for(lambda: gone(loop), timeout_s=40), "the loop process did not end"
    assert set(torque_now(emu, robot).values()) == {0}
    goals = [p for p in emu.log() if p.instruction == "sync_write" and p.address == 116]
    assert goals and goals[-1].values == {j.servo_id: t for j, t in zip(
        robot.joints, rest_goals(robot), strict=True)}            # it rested first


def test_loop_frozen_then_back_is_shown_then_stopped(emu: Emulator, robot: RobotConfig,
                                                     robot_toml: Path, tmp_path: Path) -> None:
    """The loop process frozen (SIGSTOP) for longer than the servos' Bus Watchdog: the
    panel says the loop is not answering; when it runs again it finds the gap and stops
    at once (torque off), never a silent "walking"."""
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        (loop,) = children(panel.proc.pid)
        os.kill(loop, signal.SIGSTOP)
        try:
            assert wait_for(lambda: panel.state()["state"] == "fault", timeout_s=10)
            assert "did not answer" in panel.state()["fault"]
            assert wait_for(lambda: {emu.registers(i)["bus_watchdog"] for i in robot.ids}
                            == {-1})                            # the servos stopped
        finally:
            os.kill(loop, signal.SIGCONT)
        assert wait_for(lambda: not panel.state()["running"]), panel.state()
        s = panel.state()
        assert "stalled" in (s["fault"] or ""), s
        assert set(torque_now(emu, robot).values()) == {0}
        panel.proc.send_signal(INT)
        code, out = end(panel)
    assert code == 130 and out.splitlines()[-1].endswith("torque off"), out


def test_a_starved_loop_is_shown_late_then_stopped(emu: Emulator, robot: RobotConfig,
                                                   robot_toml: Path, tmp_path: Path) -> None:
    """The loop process gets 30 ms of every 100 (frozen the rest, never long enough to
    trip the servos' Bus Watchdog): the panel shows it late while it walks, then the run
    ends as a fault (ramped out to rest, torque off), never a silent "walking"."""
    with launched(emu, robot_toml, tmp_path, "--set", "ramp_cycles=0.3", start=True,
                  rate=RATE) as panel:
        walking(panel)
        (loop,) = children(panel.proc.pid)
        seen: set[str] = set()
        t, end_at, k = time.monotonic(), time.monotonic() + 20.0, 0
        try:
            while time.monotonic() < end_at:
                os.kill(loop, signal.SIGSTOP)
                sleep_until(t + 0.07)
                os.kill(loop, signal.SIGCONT)
                sleep_until(t + 0.1)
                t, k = t + 0.1, k + 1
                if k % 5 == 0:
                    s = panel.state()
                    seen.add(s["state"])
                    if not s["running"]:
                        break
        finally:
            os.kill(loop, signal.SIGCONT)
        assert wait_for(lambda: not panel.state()["running"]), panel.state()
        s = panel.state()
        assert "late" in seen, seen
        assert "late" in (s["fault"] or "") and "safe stop" in s["fault"], s
        assert set(torque_now(emu, robot).values()) == {0}
        assert [emu.registers(j.servo_id)["goal_position"] for j in robot.joints] == \
            rest_goals(robot)                                   # ramped out to rest


@pytest.mark.parametrize("fault", ["overheating", "drop100"])
def test_a_bus_fault_mid_walk_is_shown_and_torque_goes_off(
        emu: Emulator, robot: RobotConfig, robot_toml: Path, tmp_path: Path,
        fault: str) -> None:
    """A servo's hardware error flag, or a bus that stops answering: the run stops at
    once on the watchdog, torque off at the wire, the panel shows why and serves on;
    a new start works once the bus is well again."""
    knee = robot.joint("l_knee").servo_id
    with launched(emu, robot_toml, tmp_path, start=True, rate=RATE) as panel:
        walking(panel)
        if fault == "drop100":
            emu.set_faults(drop_rate=1.0)
        else:
            emu.set_faults(hw_error={knee: fault})
        assert wait_for(lambda: not panel.state()["running"]), panel.state()
        s = panel.state()
        assert s["fault"] and s["fault"].startswith("watchdog"), s
        assert ("bus errors" if fault == "drop100" else f"reports {fault}") in s["fault"]
        assert set(torque_now(emu, robot).values()) == {0}
        emu.clear_faults()
        if fault == "drop100":
            assert panel.request("POST", "/api/start")[0] == 200
            walking(panel)
        panel.proc.send_signal(INT)
        code, out = end(panel)
    assert code == 130 and out.splitlines()[-1].endswith("torque off"), out
    assert set(torque_now(emu, robot).values()) == {0}
