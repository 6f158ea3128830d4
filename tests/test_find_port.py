"""`biped find-port` on fake device lists: the pure comparison, `run()` with an injected
lister and scripted answers, and the real lister and CLI on pyserial with its backend
replaced (tests/fake_comports.py; in a subprocess for the CLI, real stdin)."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from fake_comports import serve, write_listings

from robot.commands.find_port import run
from robot.setup.serial_ports import (
    PortSearchError,
    SerialPort,
    added_port,
    list_ports,
    removed_port,
)

REPO = Path(__file__).resolve().parent.parent

U2D2 = SerialPort("/dev/ttyUSB0", "USB <-> Serial Converter", 0x0403, 0x6014, "FT6Z5XXX",
                  "FTDI", "USB <-> Serial Converter")
CH340 = SerialPort("/dev/ttyUSB1", "USB Serial", 0x1A86, 0x7523, None, None, "USB Serial")
ARDUINO = SerialPort("/dev/ttyACM0", "Arduino Uno", 0x2341, 0x0043, "7573", "Arduino (www."
                     "arduino.cc)", None)
U2D2_BACK = SerialPort("/dev/ttyUSB2", U2D2.description, U2D2.vid, U2D2.pid,
                       U2D2.serial_number, U2D2.manufacturer, U2D2.product)


def test_removed_port_is_the_one_that_went_away() -> None:
    assert removed_port([U2D2, CH340, ARDUINO], [CH340, ARDUINO]) == U2D2
    assert removed_port([CH340], []) == CH340


@pytest.mark.parametrize(("before", "after", "needle"), [
    ([U2D2, CH340], [U2D2, CH340], "no serial port went away"),
    ([U2D2, CH340, ARDUINO], [ARDUINO], "2 serial ports went away (/dev/ttyUSB0, "
     "/dev/ttyUSB1)"),
    ([], [], "no serial port went away"),
])
def test_removed_port_refuses_zero_or_several(before: list[SerialPort],
                                              after: list[SerialPort], needle: str) -> None:
    with pytest.raises(PortSearchError) as e:
        removed_port(before, after)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_added_port() -> None:
    assert added_port([CH340], [CH340, U2D2_BACK]) == U2D2_BACK
    with pytest.raises(PortSearchError, match="no serial port came back"):
        added_port([CH340], [CH340])
    with pytest.raises(PortSearchError, match="2 serial ports appeared"):
        added_port([], [CH340, U2D2])


def test_port_summary_and_vendor_from_vid() -> None:
    assert U2D2.summary() == ("/dev/ttyUSB0 (FTDI USB <-> Serial Converter, 0403:6014, "
                              "serial FT6Z5XXX)")
    assert CH340.vendor == "QinHeng Electronics" and CH340.vid_pid == "1a86:7523"
    assert SerialPort("/dev/ttyS0", "n/a").summary() == "/dev/ttyS0"
    assert SerialPort.from_dict(U2D2.as_dict()) == U2D2


def test_real_lister_runs_here() -> None:
    """pyserial's list on this machine (no adapter here: usually empty) gives SerialPorts."""
    assert all(isinstance(p, SerialPort) for p in list_ports())


def scripted(listings: list[list[SerialPort]]) -> Callable[[], list[SerialPort]]:
    calls = iter(listings)
    last: list[list[SerialPort]] = []

    def lister() -> list[SerialPort]:
        last[:] = [next(calls, last[0] if last else [])]
        return list(last[0])
    return lister


def ns(**kw: bool) -> argparse.Namespace:
    return argparse.Namespace(**{"list": False, "json": False, **kw})


def test_run_unplug_replug_reports_the_new_name(capsys: pytest.CaptureFixture[str]) -> None:
    answers = iter(["\n", "\n"])
    lister = scripted([[U2D2, CH340], [CH340], [CH340, U2D2_BACK]])
    assert run(ns(), lister=lister, read_line=lambda: next(answers), settle_s=0) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "2 serial adapter(s):"
    assert any("0403:6014" in line and "FT6Z5XXX" in line for line in out)
    assert out[-1] == ("robot's adapter: /dev/ttyUSB2 (FTDI USB <-> Serial Converter, "
                       "0403:6014, serial FT6Z5XXX) (it was /dev/ttyUSB0 before); "
                       "use --port /dev/ttyUSB2")


def test_run_eof_is_one_line_error() -> None:
    with pytest.raises(PortSearchError, match="no answer on stdin"):
        run(ns(), lister=scripted([[U2D2]]), read_line=lambda: "", settle_s=0)


def test_run_list_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(ns(list=True, json=True), lister=scripted([[U2D2, ARDUINO]])) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["device"] for r in rows] == ["/dev/ttyUSB0", "/dev/ttyACM0"]
    assert rows[0]["vid_pid"] == "0403:6014" and rows[0]["vendor"] == "FTDI"
    assert rows[1]["serial_number"] == "7573" and rows[1]["description"] == "Arduino Uno"


def biped(argv: list[str], ports: Path, stdin: str) -> subprocess.CompletedProcess[str]:
    code = ("import sys; sys.path.insert(1, 'tests'); import fake_comports as f; "
            "sys.exit(f.main(sys.argv[1:]))")
    return subprocess.run([sys.executable, "-c", code, str(ports), *argv], cwd=REPO,
                          input=stdin, capture_output=True, text=True, timeout=60,
                          env=dict(os.environ))


def test_list_ports_reads_pyserial_sorted(monkeypatch: pytest.MonkeyPatch) -> None:
    serve(monkeypatch, [[U2D2, ARDUINO, CH340], [CH340]])
    assert list_ports() == [ARDUINO, U2D2, CH340]   # by device name
    assert list_ports() == [CH340]
    assert list_ports() == [CH340]   # the last listing stays


def test_run_defaults_to_pyserial(monkeypatch: pytest.MonkeyPatch,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    serve(monkeypatch, [[U2D2, CH340], [CH340], [CH340, U2D2_BACK]])
    answers = iter(["\n", "\n"])
    assert run(ns(json=True), read_line=lambda: next(answers), settle_s=0) == 0
    found = json.loads(capsys.readouterr().out)
    assert found["device"] == "/dev/ttyUSB2" and found["serial_number"] == "FT6Z5XXX"


def test_help_has_no_test_hook() -> None:
    r = subprocess.run([sys.executable, "-c", "import sys, robot.cli as c; "
                        "c.COMMANDS = ('find_port',); sys.exit(c.main(sys.argv[1:]))",
                        "find-port", "--help"], cwd=REPO, capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert "find the robot's" in r.stdout
    assert "BIPED_FAKE_PORTS" not in r.stdout and "test hook" not in r.stdout.lower()


def test_cli_same_port_back_json(tmp_path: Path) -> None:
    ports = write_listings(tmp_path / "ports.json", [[ARDUINO, U2D2], [ARDUINO], [ARDUINO, U2D2]])
    r = biped(["find-port", "--json"], ports, "\n\n")
    assert r.returncode == 0, r.stderr
    found = json.loads(r.stdout)
    assert found["device"] == "/dev/ttyUSB0" and found["vid_pid"] == "0403:6014"
    assert "Unplug the robot's USB adapter" in r.stderr


def test_cli_text(tmp_path: Path) -> None:
    ports = write_listings(tmp_path / "ports.json", [[ARDUINO, CH340], [ARDUINO], [ARDUINO, CH340]])
    r = biped(["find-port"], ports, "\n\n")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == ("robot's adapter: /dev/ttyUSB1 (QinHeng Electronics "
                                         "USB Serial, 1a86:7523); use --port /dev/ttyUSB1")


@pytest.mark.parametrize(("listings", "needle"), [
    ([[ARDUINO, U2D2]], "no serial port went away"),
    ([[ARDUINO, U2D2, CH340], [ARDUINO]], "2 serial ports went away"),
    ([[]], "no serial adapters found"),
])
def test_cli_refusals_are_one_line(tmp_path: Path, listings: list[list[SerialPort]],
                                   needle: str) -> None:
    r = biped(["find-port"], write_listings(tmp_path / "ports.json", listings), "\n\n")
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and needle in r.stderr, r.stderr
    assert r.stderr.startswith("biped find-port: error: ")
