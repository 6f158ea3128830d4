"""Issue 8, item 11: every bad file or value is refused before anything moves: exit code 2,
exactly one line on stderr naming the file or option, the field and the valid range, no
traceback; on the emulated bus, not one byte reaches the servos.

Expected ranges are written out here by hand (they are the documented contract), not read
from the code under test.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from bus_harness import TEST_TIMEOUT_MS

import robot.cli as cli
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.motion.ramp import ramp, ramp_duration
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

REPO = Path(__file__).resolve().parent.parent
BIG = "1" + "0" * 399                     # a 400-digit integer
DXL_BAUDS = "9600, 57600, 115200, 1000000, 2000000, 3000000, 4000000"
GEOMETRY = ("hip_width", "thigh", "shin", "ankle_height", "foot_length", "foot_width",
            "foot_forward", "torso_height", "torso_depth", "shoulder_width", "upper_arm",
            "forearm")
MASSES = ("torso", "hip_yaw_link", "hip_roll_link", "thigh", "shin", "ankle_link", "foot",
          "shoulder_link", "upper_arm", "forearm")
JOINT_RANGES = {"servo_id": "[0, 252]", "zero_ticks": "[0, 4095]", "min_rad": "[-pi, pi] rad",
                "max_rad": "[-pi, pi] rad", "max_speed_rad_s": "[0.05, 20] rad/s",
                "sign": "+1 or -1"}


def base_robot(protocol: str = "dynamixel") -> str:
    # A reply timeout that tolerates a busy test machine (the harness's, tests/bus_harness.py).
    text = (ROBOTS_DIR / f"biped18-{protocol}.toml").read_text()
    return text.replace("timeout_ms = 20.0", f"timeout_ms = {TEST_TIMEOUT_MS}")


def set_field(text: str, table: str, key: str, value: str) -> str:
    """``key = value`` inside ``[table]`` of a robot TOML text."""
    head = f"[{table}]"
    i = text.index(head)
    j = text.find("\n[", i + 1)
    j = len(text) if j < 0 else j
    block, n = re.subn(rf"^{key} = [^#\n]*", f"{key} = {value}", text[i:j], count=1, flags=re.M)
    assert n == 1, f"{table}.{key} not in the base robot"
    return text[:i] + block + text[j:]


def run_cli(argv: list[str], capsys: pytest.CaptureFixture[str],
            monkeypatch: pytest.MonkeyPatch) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``biped <argv>`` in-process. Only the command under test
    is built (others may be mid-edit); argparse's own exit counts like a returned code."""
    monkeypatch.setattr(cli, "COMMANDS", (cli.command_of(argv) or argv[0],))  # import_
    try:
        code = cli.main(argv)
    except SystemExit as e:
        code = int(e.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def assert_refused(code: int, err: str, *needles: str) -> str:
    """Exit 2, exactly one line on stderr containing every needle, no traceback."""
    assert code == 2, err
    assert "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1, err
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


# ------------------------------------------------------------------- bad robot files


ROBOT_EDITS: dict[str, tuple[Callable[[str], str], tuple[str, ...]]] = {
    "max_rad pi at zero_ticks 2048 (tick 4096)": (
        lambda t: set_field(t, "joints.r_knee", "max_rad", "3.141592653589793"),
        ("joints.r_knee.max_rad:", "tick 4096", "within [-3.1415, 3.1400] rad")),
    "zero_ticks 100 (negative goals)": (
        lambda t: set_field(t, "joints.r_hip_roll", "zero_ticks", "100"),
        # -0.5 rad: 100 - 0.5 * 651.9 = -225.95 ticks; the first whole tick inside is -225.
        ("joints.r_hip_roll.min_rad:", "tick -225", "within [-0.1533, 3.1415] rad")),
    "max_speed_rad_s 1e-9": (
        lambda t: set_field(t, "joints.r_knee", "max_speed_rad_s", "1e-9"),
        ("joints.r_knee.max_speed_rad_s: expected a number in [0.05, 20] rad/s, got 1e-09",)),
    "thigh 1e300": (
        lambda t: set_field(t, "geometry", "thigh", "1e300"),
        ("geometry.thigh: expected a number in [0.001, 2] m, got 1e+300",)),
    "mass 1e300": (
        lambda t: set_field(t, "mass", "torso", "1e300"),
        ("mass.torso: expected a number in [0.001, 100] kg, got 1e+300",)),
    "retries -1": (
        lambda t: set_field(t, "bus", "retries", "-1"),
        ("bus.retries: expected an integer in [0, 10], got -1",)),
    "timeout_ms 0": (
        lambda t: set_field(t, "bus", "timeout_ms", "0"),
        ("bus.timeout_ms: expected a number in [1, 1000] ms, got 0",)),
    "non-standard baud": (
        lambda t: set_field(t, "bus", "baud", "115201"),
        ("bus.baud: expected a", "baud rate (one of", "got 115201")),
    "a 400-digit integer": (
        lambda t: set_field(t, "joints.r_knee", "zero_ticks", BIG),
        ("joints.r_knee.zero_ticks: expected an integer in [0, 4095], got an integer of "
         "400 digits",)),
    "a 5000-digit integer": (
        lambda t: set_field(t, "bus", "retries", "9" * 5000),
        ("not valid TOML: an integer has more than 4300 digits",)),
}


def write_bad_robot(tmp: Path, case: str, protocol: str = "dynamixel") -> tuple[Path, tuple[str, ...]]:
    edit, needles = ROBOT_EDITS[case]
    path = tmp / "bad-robot.toml"
    path.write_text(edit(base_robot(protocol)))
    return path, needles


@pytest.mark.parametrize("case", sorted(ROBOT_EDITS))
def test_bad_robot_value_is_one_line(case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    path, needles = write_bad_robot(tmp_path, case)
    code, out, err = run_cli(["curves", "--robot", str(path), "--out", str(tmp_path / "c.csv")],
                             capsys, monkeypatch)
    assert_refused(code, err, f"biped curves: error: {path}: ", *needles)
    assert out == "" and not (tmp_path / "c.csv").exists()


def big_int_cases() -> Iterator[tuple[str, str, str, str]]:
    """(table, key, field path, expected range) for every numeric field of a robot file."""
    yield "bus", "baud", "bus.baud", f"one of {DXL_BAUDS}"
    yield "bus", "retries", "bus.retries", "[0, 10]"
    yield "bus", "timeout_ms", "bus.timeout_ms", "[1, 1000] ms"
    for g in GEOMETRY:   # the sole's centre may sit behind the ankle (an imported foot)
        yield "geometry", g, f"geometry.{g}", "[-0.5, 0.5] m" if g == "foot_forward" else "[0.001, 2] m"
    for m in MASSES:
        yield "mass", m, f"mass.{m}", "[0.001, 100] kg"
    for k, rng in JOINT_RANGES.items():
        yield "joints.l_knee", k, f"joints.l_knee.{k}", rng
    yield "rest", "r_knee", "rest.r_knee", "[-pi, pi] rad"


@pytest.mark.parametrize("table, key, field, valid", list(big_int_cases()))
@pytest.mark.parametrize("sign", ["", "-"])
def test_400_digit_integer_in_any_robot_field(table: str, key: str, field: str, valid: str,
                                              sign: str, tmp_path: Path) -> None:
    path = tmp_path / "big.toml"
    path.write_text(set_field(base_robot(), table, key, sign + BIG))
    with pytest.raises(ConfigError) as info:
        load_robot(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: {field}: expected ") and "\n" not in msg, msg
    assert valid in msg and f"got {sign}an integer of 400 digits" in msg, msg


@pytest.mark.parametrize("content, needle", [
    (bytes(range(256)) * 4, "not a UTF-8 text file (byte 0x80 at offset 128); expected a TOML file"),
    (bytes(range(1, 128)), "not valid TOML: "),
    ('name = "caf\u00e9"\n'.encode("latin-1"), "not a UTF-8 text file (byte 0xe9 at offset 11)"),
    (b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n", "not valid TOML: arrays or tables nested too deeply"),
    (b"# x\n" * 300_000, "larger than 1024 KiB; expected a TOML file"),
])
@pytest.mark.parametrize("option", ["--robot", "--gait"])
def test_garbage_toml_file_is_one_line(content: bytes, needle: str, option: str, tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str],
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "garbage.toml"
    path.write_bytes(content)
    code, _, err = run_cli(["curves", option, str(path), "--out", str(tmp_path / "c.csv")],
                           capsys, monkeypatch)
    assert_refused(code, err, f"{path}: {needle}")


@pytest.mark.parametrize("option", ["--robot", "--gait"])
@pytest.mark.parametrize("kind", ["directory", "device"])
def test_directory_or_device_as_toml_file(option: str, kind: str, tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str],
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    # /dev/zero used to be read until memory ran out.
    path, needle = ((tmp_path / "conf.toml", "is a directory; expected a TOML file")
                    if kind == "directory" else
                    (Path("/dev/zero"), "not a regular file (a device or pipe)"))
    if kind == "directory":
        path.mkdir()
    code, _, err = run_cli(["curves", option, str(path), "--out", str(tmp_path / "c.csv")],
                           capsys, monkeypatch)
    assert_refused(code, err, f"{path}: {needle}")


@pytest.mark.parametrize("text, needle", [
    (f"[params]\nvM = {BIG}\n", "params.vM: vM = an integer of 400 digits is outside [0, 2] "
                                "rad/frame"),
    (f"[params]\nvM = -{BIG}\n", "params.vM: vM = -an integer of 400 digits is outside [0, 2]"),
    ("[params]\nSlgt_R = 1e300\n", "params.Slgt_R: Slgt_R = 1e+300 is outside [0, 3] rig"),
    (f"fps = {BIG}\n", "fps: fps = an integer of 400 digits is outside [1, 240] frame/s"),
    (f"[mapping]\nsway = {BIG}\n", "mapping.sway: sway = an integer of 400 digits is outside "
                                   "[0, 0.06] m"),
])
def test_gait_file_with_huge_numbers(text: str, needle: str, tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str],
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "huge.toml"
    path.write_text(text)
    code, _, err = run_cli(["curves", "--gait", str(path), "--out", str(tmp_path / "c.csv")],
                           capsys, monkeypatch)
    assert_refused(code, err, f"{path}: {needle}")


# ------------------------------------------------------------- files as another user


@pytest.fixture
def shared_dir() -> Iterator[Path]:
    """A directory another user can enter (pytest's tmp_path is private to root)."""
    d = Path(tempfile.mkdtemp(prefix="biped-bad-input-"))
    d.chmod(0o755)
    yield d
    for p in [d, *d.rglob("*")]:
        p.chmod(0o755) if p.is_dir() else p.chmod(0o644)
    shutil.rmtree(d)


def run_unprivileged(argv: list[str]) -> subprocess.CompletedProcess[str]:
    """``python -m robot.cli <argv>`` as an unprivileged user: root reads and writes
    through any permission bits, so a permission test as root would prove nothing."""
    prefix = (["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"]
              if os.geteuid() == 0 else [])
    env = {**os.environ, "HOME": "/tmp", "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run([*prefix, sys.executable, "-m", "robot.cli", *argv], cwd=REPO,
                          env=env, capture_output=True, text=True, timeout=60)


def test_unreadable_robot_file(shared_dir: Path) -> None:
    path = shared_dir / "secret.toml"
    path.write_text(base_robot())
    path.chmod(0o000)
    out = shared_dir / "w"
    out.mkdir()
    out.chmod(0o777)  # writable by anyone: the robot file is the only problem
    r = run_unprivileged(["curves", "--robot", str(path), "--out", str(out / "c.csv")])
    assert_refused(r.returncode, r.stderr, f"{path}: cannot read: Permission denied")
    assert list(out.iterdir()) == []


def test_read_only_output_directory(shared_dir: Path) -> None:
    ro = shared_dir / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    r = run_unprivileged(["curves", "--out", str(ro / "c.csv")])
    assert_refused(r.returncode, r.stderr, "--out", f"directory {ro} is not writable; "
                   "expected a writable file path")
    assert list(ro.iterdir()) == []


# ------------------------------------------------------------------- bad options


@pytest.mark.parametrize("extra, needles", [
    (["--rate", "0"], ("argument --rate: expected a rate in [1, 2000] Hz, got '0'",)),
    (["--rate", "1e9"], ("argument --rate: expected a rate in [1, 2000] Hz, got '1e9'",)),
    (["--rate", "nan"], ("argument --rate: expected a rate in [1, 2000] Hz, got 'nan'",)),
    (["--rate", "fast"], ("argument --rate: expected a rate in [1, 2000] Hz, got 'fast'",)),
    (["--seconds", "1e7"], ("argument --seconds: expected a duration in (0, 1e+06] s",)),
    (["--seconds", "0"], ("argument --seconds: expected a duration in (0, 1e+06] s, got '0'",)),
    (["--seconds", "inf"], ("argument --seconds: expected a duration in (0, 1e+06] s",)),
    (["--seconds", BIG], ("argument --seconds: expected a duration in (0, 1e+06] s, got "
                          f"'{BIG[:40]}'... (400 chars)",)),
    (["--seconds", "1e6", "--rate", "2000"],
     ("--seconds 1e+06 x --rate 2000: 2000000001 rows; expected at most 1000000",)),
])
def test_curves_option_out_of_range(extra: list[str], needles: tuple[str, ...], tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "c.csv"
    code, _, err = run_cli(["curves", "--out", str(out), *extra], capsys, monkeypatch)
    assert_refused(code, err, "biped curves: error: ", *needles)
    assert not out.exists()


def unwritable_paths(tmp: Path) -> dict[str, tuple[str, str]]:
    """name → (path, the reason in the message)."""
    (tmp / "a_dir").mkdir()
    (tmp / "a_file").write_text("x")
    return {
        "missing directory": (str(tmp / "nowhere" / "x.out"),
                              f"directory {tmp / 'nowhere'} does not exist"),
        "a directory": (str(tmp / "a_dir"), f"'{tmp / 'a_dir'}' is a directory"),
        "parent is a file": (str(tmp / "a_file" / "x.out"), f"{tmp / 'a_file'} is not a directory"),
    }


@pytest.mark.parametrize("which", ["missing directory", "a directory", "parent is a file"])
@pytest.mark.parametrize("cmd", [
    ["curves", "--out", "{p}"],
    ["curves", "--out", "{tmp}/ok.csv", "--plot", "{p}"],
    ["render", "--quiet", "--out", "{p}"],
    ["plot", "{tmp}/a_file", "--out", "{p}"],
])
def test_unwritable_output_is_refused_before_any_work(which: str, cmd: list[str], tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str],
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    path, reason = unwritable_paths(tmp_path)[which]
    argv = [a.format(p=path, tmp=tmp_path) for a in cmd]
    code, out, err = run_cli(argv, capsys, monkeypatch)
    option = "--plot" if "--plot" in cmd else "--out"
    assert_refused(code, err, option, reason, "expected a writable file path")
    assert out == "" and not (tmp_path / "ok.csv").exists()


def test_mjcf_out_under_a_file(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                               monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "a_file").write_text("x")
    code, _, err = run_cli(["mjcf", "--out", str(tmp_path / "a_file" / "sub")], capsys,
                           monkeypatch)
    assert_refused(code, err, f"--out: {tmp_path / 'a_file'} is not a directory; expected a "
                              "writable directory")


@pytest.mark.parametrize("extra, needle", [
    (["--seconds", "1e5"], "argument --seconds: expected a clip length in (0, 3600] s"),
    (["--fps", "0"], "argument --fps: expected a frame rate in [1, 120] frames/s, got '0'"),
    (["--rate", "1e9"], "argument --rate: expected a rate in [1, 2000] Hz"),
    (["--width", BIG], "argument --width: expected a frame size in [1, 100000] px"),
    (["--seconds", "3600", "--width", "1920", "--height", "1080"],
     # 3600 s x 30 fps x 1920 x 1080 x 3 bytes = 6.72e11 bytes = 625.7 GiB
     "a GIF of 108000 frames of 1920x1080 needs 625.7 GiB in memory; expected at most 1 GiB"),
])
def test_render_option_out_of_range(extra: list[str], needle: str, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "clip.gif"
    code, _, err = run_cli(["render", "--out", str(out), "--quiet", *extra], capsys, monkeypatch)
    assert_refused(code, err, "biped render: error: ", needle)
    assert not out.exists()


def test_mjcf_timestep_out_of_range(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    code, _, err = run_cli(["mjcf", "--out", str(tmp_path / "m"), "--timestep", "1e300"],
                           capsys, monkeypatch)
    assert_refused(code, err, "argument --timestep: expected a timestep in (0, 0.01] s")
    assert not (tmp_path / "m").exists()


# ------------------------------------------------------------------- ramps


def test_ramp_refuses_an_absurd_duration_instead_of_allocating() -> None:
    # 1 rad at 1e-9 rad/s: 1.875e9 s, i.e. 3.75e11 rows at 200 Hz (the 307 GiB of the issue).
    with pytest.raises(ConfigError, match=r"ramp: would last 1.88e\+09 s .* at most 300 s"):
        ramp([0.0], [1.0], 1e-9, 200.0)
    with pytest.raises(ConfigError, match=r"at most 300 s"):
        ramp_duration([0.0], [1.0], 1e-9)
    with pytest.raises(ConfigError, match=r"at most 300 s"):
        ramp([0.0], [0.0], 1.0, 200.0, min_duration=1e12)


def test_ramp_refuses_too_many_steps() -> None:
    # 0.5 s at 1e7 Hz: 5e6 steps.
    with pytest.raises(ConfigError, match=r"is 5000000 steps; expected at most 600000"):
        ramp([0.0] * 18, [0.1] * 18, 5.0, 1e7)
    # The slowest allowed move still ramps: 2 pi at 0.05 rad/s, 236 s at 200 Hz.
    path = ramp([-math.pi], [math.pi], 0.05, 200.0)
    assert len(path) == math.ceil(1.875 * 2 * math.pi / 0.05 * 200) + 1
    assert np.all(np.abs(np.diff(path[:, 0])) <= 0.05 / 200 + 1e-12)


# ------------------------------------------------- the bus: nothing reaches a servo


@pytest.fixture(scope="module", params=("dynamixel", "feetech"))
def chain(request: pytest.FixtureRequest) -> Iterator[Emulator]:
    """One emulated chain per protocol for the whole module (each test checks the bytes it
    caused: the counters are read before and after)."""
    protocol = str(request.param)
    with Emulator(protocol, load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")) as e:
        yield e


def received(emu: Emulator) -> int:
    return emu.counters()["rx_bytes"]


def test_the_byte_counter_sees_a_good_command(chain: Emulator, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str],
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """Control: the same invocation with a good robot file does reach the servos."""
    robot = tmp_path / "good.toml"
    robot.write_text(base_robot(chain.protocol))
    before = received(chain)
    code, _, err = run_cli(["torque", "off", "--bus", chain.protocol, "--port", chain.port,
                            "--robot", str(robot)], capsys, monkeypatch)
    assert code == 0, err
    assert received(chain) > before


BUS_COMMANDS = {
    "walk": ["walk", "--seconds", "0.5"],
    "torque on": ["torque", "on"],
    "torque off": ["torque", "off"],
    "pose": ["pose", "rest"],
    "scan": ["scan", "--ids", "1-3"],
}
BUS_CASES = ["max_rad pi at zero_ticks 2048 (tick 4096)", "zero_ticks 100 (negative goals)",
             "max_speed_rad_s 1e-9", "thigh 1e300", "retries -1", "timeout_ms 0",
             "non-standard baud", "a 400-digit integer"]


@pytest.mark.parametrize("case", BUS_CASES)
@pytest.mark.parametrize("command", sorted(BUS_COMMANDS))
def test_bad_robot_file_fails_before_the_port_is_used(chain: Emulator, command: str, case: str,
                                                     tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str],
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    path, needles = write_bad_robot(tmp_path, case, chain.protocol)
    before = received(chain)
    argv = [*BUS_COMMANDS[command], "--bus", chain.protocol, "--port", chain.port,
            "--robot", str(path)]
    code, out, err = run_cli(argv, capsys, monkeypatch)
    assert_refused(code, err, f"{path}: ", *needles)
    assert out == ""
    assert received(chain) == before, "bytes reached the servos"
    assert {chain.registers(i)["torque_enable"] for i in chain.ids} == {0}


@pytest.mark.parametrize("command", ["torque on", "scan"])
@pytest.mark.parametrize("extra, needle", [
    (["--baud", "12345"], "argument --baud: expected a standard servo baud rate (9600, 19200, "
                          "38400, 57600, 76800, 115200, 128000, 200000, 250000, 400000, "
                          "500000, 1000000, 2000000, 3000000, 4000000), got '12345'"),
    (["--baud", BIG], "argument --baud: expected a standard servo baud rate"),
])
def test_non_standard_baud_option(chain: Emulator, command: str, extra: list[str], needle: str,
                                  capsys: pytest.CaptureFixture[str],
                                  monkeypatch: pytest.MonkeyPatch) -> None:
    before = received(chain)
    argv = [*BUS_COMMANDS[command], "--bus", chain.protocol, "--port", chain.port, *extra]
    code, _, err = run_cli(argv, capsys, monkeypatch)
    assert_refused(code, err, needle)
    assert received(chain) == before


@pytest.mark.parametrize("command", ["torque on", "torque off", "scan"])
def test_baud_of_the_other_family(chain: Emulator, command: str, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str],
                                  monkeypatch: pytest.MonkeyPatch) -> None:
    # 4 Mbps is a Dynamixel X rate only; 250 kbps a Feetech STS rate only.
    baud, valid = (("250000", DXL_BAUDS) if chain.protocol == "dynamixel" else
                   ("4000000", "38400, 57600, 76800, 115200, 128000, 250000, 500000, 1000000"))
    robot = tmp_path / "r.toml"
    robot.write_text(base_robot(chain.protocol))
    before = received(chain)
    argv = [*BUS_COMMANDS[command], "--bus", chain.protocol, "--port", chain.port,
            "--robot", str(robot), "--baud", baud]
    code, _, err = run_cli(argv, capsys, monkeypatch)
    assert_refused(code, err, f"--baud {baud}: expected a {chain.protocol} baud rate (one of "
                              f"{valid})")
    assert received(chain) == before


@pytest.mark.parametrize("ids, shown", [
    ("1-100000000", "'1-100000000'"), ("300", "'300'"), ("5-1", "'5-1'"), ("a", "'a'"),
    ("1,,2", "''"), (BIG, f"'{BIG[:40]}'... (400 chars)"),
])
def test_scan_ids_out_of_range(chain: Emulator, ids: str, shown: str,
                               capsys: pytest.CaptureFixture[str],
                               monkeypatch: pytest.MonkeyPatch) -> None:
    before = received(chain)
    code, _, err = run_cli(["scan", "--bus", chain.protocol, "--port", chain.port, "--ids", ids],
                           capsys, monkeypatch)
    assert_refused(code, err, "argument --ids: expected ids or ranges in [0, 252] like 1-20 "
                              f"or 1,3,5-7, got {shown}")
    assert received(chain) == before


@pytest.mark.parametrize("argv, needle", [
    (["walk", "--record", "/nonexistent-dir/run.csv"],
     "argument --record: directory /nonexistent-dir does not exist; expected a writable"),
    (["walk", "--record", "."], "argument --record: "),
    (["walk", "--rate", "1e9"], "argument --rate: "),
    (["walk", "--rate", "0"], "argument --rate: "),
    (["walk", "--seconds", "1e300"], "argument --seconds: "),
    (["walk", "--baud", "12345"], "argument --baud: expected a standard servo baud rate"),
    (["pose", "rest", "--speed", "1e-9"], "argument --speed: "),
    (["pose", "rest", "--rate", "-5"], "argument --rate: "),
])
def test_walk_and_pose_options_refused_before_the_port_is_used(
        chain: Emulator, argv: list[str], needle: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    robot = tmp_path / "r.toml"
    robot.write_text(base_robot(chain.protocol))
    before = received(chain)
    code, out, err = run_cli([*argv, "--bus", chain.protocol, "--port", chain.port,
                              "--robot", str(robot)], capsys, monkeypatch)
    assert_refused(code, err, needle)
    assert out == ""
    assert received(chain) == before, "bytes reached the servos"
