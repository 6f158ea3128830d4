"""`biped setup-motors` end to end on factory-new emulated servos (every bus kind)."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from bus_harness import TEST_TIMEOUT_MS

import robot.cli as cli
from robot.commands import setup_motors
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.servo.models import BAUD_CODES, BUS_FAMILIES
from robot.setup.motor_setup import FACTORY_BAUD, baud_order
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
JOINTS = ("r_hip_yaw", "r_knee", "l_elbow")          # ids 1, 4, 18
OTHER_MODEL = {"dynamixel": "XM430-W350", "feetech": "STS3032"}
WRITES = ("write", "sync_write", "bulk_write", "reg_write")


@pytest.fixture(autouse=True)
def only_this_command(monkeypatch: pytest.MonkeyPatch) -> None:
    """Build the CLI from the command under test only (others may be unfinished)."""
    monkeypatch.setattr(cli, "COMMANDS", ("setup_motors", "scan"))


@pytest.fixture
def fresh(protocol: str) -> Iterator[Emulator]:
    with Emulator.factory_new(protocol, len(JOINTS)) as e:
        yield e


def setup(emu: Emulator, robot_toml: Path, *extra: str) -> int:
    return cli.main(["setup-motors", "--robot", str(robot_toml), "--bus", emu.protocol,
                     "--port", emu.port, *extra])


def writes(emu: Emulator) -> list[str]:
    return [p.instruction for p in emu.log() if p.instruction in WRITES]


def test_baud_order_puts_factory_and_robot_rates_first() -> None:
    for family, codes in BAUD_CODES.items():
        order = baud_order(family, 1_000_000)
        assert order[0] == FACTORY_BAUD[family]
        assert order[1] == 1_000_000 or FACTORY_BAUD[family] == 1_000_000
        assert sorted(order) == sorted(codes.values())


def test_each_new_servo_gets_its_joint_id_and_the_robot_baud(
        fresh: Emulator, robot: RobotConfig, robot_toml: Path, bus_factory,
        capsys: pytest.CaptureFixture[str]) -> None:
    family = robot.bus.servo.family
    for index, joint in enumerate(JOINTS):
        fresh.plug(index)
        assert setup(fresh, robot_toml, "--joint", joint, "--yes") == 0
        out = capsys.readouterr().out
        assert f"{joint}: id {robot.joint(joint).servo_id} at {robot.bus.baud} baud" in out
        regs = fresh.registers_of(index)
        assert regs["id"] == robot.joint(joint).servo_id
        assert BAUD_CODES[family][regs["baud_rate"]] == robot.bus.baud
        assert regs["return_delay_time"] == 0
        assert regs["torque_enable"] == 0
        if fresh.protocol == "dynamixel":   # factory 57600 baud, return delay 500 us
            assert "baud 57600 -> 1000000" in out and "return delay 500 µs -> 0" in out
    fresh.plug_all()
    bus = bus_factory(fresh, robot, check_health=False)
    try:
        found = {s.id: s for s in bus.scan(range(0, 21))}
    finally:
        bus.close(torque_off=False)
    assert sorted(found) == sorted(robot.joint(j).servo_id for j in JOINTS)
    assert {s.model for s in found.values()} == {robot.bus.servo.number}
    assert {s.return_delay_us for s in found.values()} == {0.0}


def test_two_servos_connected_is_refused_with_nothing_written(
        fresh: Emulator, robot_toml: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fresh.plug_all()          # three new servos, all id 1 at the factory baud
    fresh.log(clear=True)
    assert setup(fresh, robot_toml, "--joint", "r_knee", "--yes") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "more than one servo answers as id" in err, err
    # three replies at once collide on the wire: the search may meet the garble first at
    # another baud, where it reads as some other id; then it says so
    assert "answers as id 1 " in err or "(garbled replies)" in err, err
    assert "connect only the servo" in err
    assert writes(fresh) == []
    assert all(fresh.registers_of(i)["id"] == 1 for i in range(len(JOINTS)))


def test_a_set_up_servo_left_on_the_chain_is_refused(
        fresh: Emulator, robot_toml: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fresh.plug(0)
    assert setup(fresh, robot_toml, "--joint", "r_knee", "--yes") == 0
    fresh.plug_all()          # the r_knee servo (id 4) and two new ones at id 1
    capsys.readouterr()
    fresh.log(clear=True)
    assert setup(fresh, robot_toml, "--joint", "l_elbow", "--yes") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nothing was written" in err, err
    # The two new servos answer id 1 at once. On a starved machine that one ping can time
    # out; the set-up servo then looks alone, and is refused as set up already.
    assert "more than one servo answers as id 1" in err or "id 4 is r_knee's" in err, err
    assert writes(fresh) == []
    assert fresh.registers_of(0)["id"] == 4


def test_a_set_up_servo_alone_is_taken_only_when_the_user_says_so(
        fresh: Emulator, robot_toml: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The r_knee servo (id 4 at the robot's baud) alone on the bus, set up for l_elbow:
    --yes refuses; at the prompt "n" writes nothing and "y" gives it l_elbow's id 18."""
    fresh.plug(0)
    assert setup(fresh, robot_toml, "--joint", "r_knee", "--yes") == 0
    capsys.readouterr()
    fresh.log(clear=True)
    assert setup(fresh, robot_toml, "--joint", "l_elbow", "--yes") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert "id 4 is r_knee's" in err and "looks set up already" in err
    assert "nothing was written" in err and "without --yes" in err
    assert writes(fresh) == []
    args = cli.build_parser().parse_args(["setup-motors", "--robot", str(robot_toml),
                                          "--port", fresh.port, "--joint", "l_elbow"])
    prompts: list[str] = []
    for answer, code, servo_id in (("n", 1, 4), ("y", 0, 18)):
        prompts.clear()

        def ask(prompt: str, answer: str = answer) -> str:
            prompts.append(prompt)
            return "" if len(prompts) == 1 else answer    # Enter: it is connected

        assert setup_motors.run(args, ask=ask) == code
        assert "Give it to l_elbow? [y/N]" in prompts[1]
        assert fresh.registers_of(0)["id"] == servo_id
        if answer == "n":
            assert writes(fresh) == []


def test_wrong_model_is_refused(protocol: str, robot_toml: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    with Emulator.factory_new(protocol, 1, model=OTHER_MODEL[protocol]) as emu:
        emu.plug(0)
        emu.log(clear=True)
        assert setup(emu, robot_toml, "--joint", "r_knee", "--yes") == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert f"is a {OTHER_MODEL[protocol]}" in err and "for r_knee" in err
        assert "bus.model" in err
        assert writes(emu) == []


#: One bundled robot per bus kind, and where a used servo was left (id, baud [bit/s]): the
#: issue's "id 4 at 57600" where the family has rates; LX has one rate, so an id that is
#: not the robot's (the first pass pings the robot's ids).
BUNDLED = {"dynamixel": "biped18-dynamixel", "dynamixel1": "biped18-ax12",
           "feetech": "biped18-feetech", "lx": "biped18-lx"}
USED = {"dynamixel": (4, 57_600), "dynamixel1": (4, 57_600), "feetech": (4, 57_600),
        "lx": (30, 115_200)}


def bundled_toml(kind: str, tmp_path: Path) -> Path:
    """The bundled robot of ``kind`` with the harness's reply timeout (a busy machine)."""
    text = (ROBOTS_DIR / f"{BUNDLED[kind]}.toml").read_text()
    path = tmp_path / f"{BUNDLED[kind]}.toml"
    path.write_text(text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}"))
    return path


@pytest.mark.parametrize("kind", sorted(BUNDLED))
def test_a_used_servo_is_found_on_every_bus_kind(kind: str, tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """Protocol 1.0 has no broadcast ping (dynamixel_sdk's broadcastPing returns
    COMM_NOT_AVAILABLE and sends nothing): the sweep pings id by id there."""
    monkeypatch.setattr("robot.setup.motor_setup.ALL_IDS", range(0, 8))   # per-id pings: short
    toml = bundled_toml(kind, tmp_path)
    robot = load_robot(toml)
    sid, baud = USED[kind]
    joint = robot.joint_by_id(5)          # not the servo's id: setup gives it id 5
    assert joint is not None
    family = BUS_FAMILIES[kind][0]
    with Emulator.factory_new(kind, 1) as emu:
        emu.plug(0)
        emu.set_register(1, "id", sid)
        if family in BAUD_CODES:
            codes = {b: c for c, b in BAUD_CODES[family].items()}
            emu.set_register(sid, "baud_rate", codes[baud])
        assert setup(emu, toml, "--joint", joint.name, "--yes") == 0, capsys.readouterr().err
        out = capsys.readouterr().out
        assert f"found: {robot.bus.model} at id {sid}, {baud} baud" in out
        regs = emu.registers_of(0)
        assert regs["id"] == 5
        if family in BAUD_CODES:
            assert BAUD_CODES[family][regs["baud_rate"]] == robot.bus.baud


@pytest.mark.parametrize("kind", sorted(BUNDLED))
def test_nothing_connected_says_no_servo_answered(kind: str, tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str],
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("robot.setup.motor_setup.ALL_IDS", range(0, 3))   # keep the sweep short
    monkeypatch.setattr("robot.setup.motor_setup.baud_order",
                        lambda family, baud: sorted({FACTORY_BAUD[family], baud}))
    toml = bundled_toml(kind, tmp_path)
    with Emulator.factory_new(kind, 1) as emu:          # one servo, unplugged
        assert setup(emu, toml, "--joint", "r_knee", "--yes") == 2
        assert writes(emu) == []
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert "no servo answered" in err and "garbled" not in err and "sharing" not in err
    assert "check its power" in err


def test_bad_options_are_one_line(fresh: Emulator, robot_toml: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    assert setup(fresh, robot_toml, "--yes") == 2
    assert "--yes needs --joint" in capsys.readouterr().err
    assert setup(fresh, robot_toml, "--joint", "tail", "--yes") == 2
    assert "no joint 'tail'" in capsys.readouterr().err
    other = "feetech" if fresh.protocol == "dynamixel" else "dynamixel"
    assert cli.main(["setup-motors", "--robot", str(robot_toml), "--bus", other, "--port",
                     fresh.port, "--joint", "r_knee", "--yes"]) == 2
    assert f"use --bus {fresh.protocol}" in capsys.readouterr().err


def test_prompts_walk_the_joints_in_order(fresh: Emulator, robot: RobotConfig,
                                          robot_toml: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    prompts: list[str] = []

    def ask(prompt: str) -> str:
        prompts.append(prompt)
        if len(prompts) > 2:
            return "q"
        fresh.plug(len(prompts) - 1)     # the user connects the next new servo
        return ""

    args = cli.build_parser().parse_args(["setup-motors", "--robot", str(robot_toml),
                                          "--port", fresh.port])
    assert setup_motors.run(args, ask=ask) == 1
    first, second = robot.joints[0], robot.joints[1]
    assert prompts[0].startswith(f"connect only the servo for {first.name} "
                                 f"(id {first.servo_id}) and press Enter")
    assert f"for {second.name} (id {second.servo_id})" in prompts[1]
    assert fresh.registers_of(0)["id"] == first.servo_id
    assert fresh.registers_of(1)["id"] == second.servo_id
    assert "stopped" in capsys.readouterr().out


def test_a_servo_at_an_odd_id_and_baud_is_found_by_the_sweep(
        protocol: str, robot: RobotConfig, robot_toml: Path,
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    family = BUS_FAMILIES[protocol][0]
    odd_baud = 115_200
    monkeypatch.setattr("robot.setup.motor_setup.ALL_IDS", range(25, 36))   # per-id pings: short
    monkeypatch.setattr("robot.setup.motor_setup.baud_order",
                        lambda fam, baud: [FACTORY_BAUD[fam], baud, odd_baud])
    with Emulator.factory_new(protocol, 1) as emu:
        emu.plug(0)
        emu.set_register(1, "id", 30)
        codes = {b: c for c, b in BAUD_CODES[family].items()}
        emu.set_register(30, "baud_rate", codes[odd_baud])
        assert setup(emu, robot_toml, "--joint", "l_knee", "--yes") == 0
        out = capsys.readouterr().out
        assert f"scanning every id at {odd_baud} baud" in out
        assert f"id 30 -> 10; baud {odd_baud} -> {robot.bus.baud}" in out
        regs = emu.registers_of(0)
        assert regs["id"] == 10 and BAUD_CODES[family][regs["baud_rate"]] == robot.bus.baud
        broadcast = [p for p in emu.log() if p.instruction == "ping" and p.ids == (0xFE,)]
        assert bool(broadcast) == (protocol == "dynamixel")   # scservo_sdk has none


def test_prompt_answered_on_stdin(fresh: Emulator, robot_toml: Path) -> None:
    """The real ``input()``: one joint with its prompt answered by a line on stdin."""
    fresh.plug(1)
    code = ("import sys, robot.cli as c; c.COMMANDS = ('setup_motors',); "
            "sys.exit(c.main(sys.argv[1:]))")
    cmd = [sys.executable, "-c", code, "setup-motors", "--robot", str(robot_toml), "--port",
           fresh.port, "--joint", "r_knee"]
    done = subprocess.run(cmd, cwd=REPO, input="\n", capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    assert "connect only the servo for r_knee (id 4) and press Enter" in done.stdout
    assert fresh.registers_of(1)["id"] == 4
    ended = subprocess.run(cmd, cwd=REPO, input="", capture_output=True, text=True,
                           timeout=60)
    assert ended.returncode == 2 and "input ended" in ended.stderr
