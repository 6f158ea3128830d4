"""`biped COMMAND` builds the parser of that command only, so it imports what the command
needs and not the simulator or the glTF writer of others; what it parses is what the whole
parser parses."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import robot.cli as cli

REPO = Path(__file__).resolve().parent.parent
#: Commands that drive servos on a bus: none needs MuJoCo or pygltflib to start.
HARDWARE = ("scan", "torque", "pose", "monitor", "setup-motors", "calibrate", "capture",
            "find-port")


def subcommands(parser: object) -> list[str]:
    """The command names a parser offers (argparse keeps them in its subparsers action)."""
    return [name for action in getattr(parser, "_actions", [])
            if action.dest == "command" for name in action.choices]


def test_every_command_name_leads_to_its_own_module() -> None:
    names = subcommands(cli.build_parser())
    assert len(names) == len(cli.COMMANDS)
    for module in cli.COMMANDS:
        (name,) = subcommands(cli.build_parser(only=module))
        assert name in names
        assert cli.command_of([name, "--help"]) == module
        assert cli.command_of(["--log-level", "DEBUG", name]) == module


@pytest.mark.parametrize("argv", [[], ["--help"], ["--version"], ["walkk"],
                                  ["--log-level=INFO", "walk"], ["--log-level"]])
def test_no_command_or_an_unknown_one_gets_the_whole_parser(argv: list[str]) -> None:
    assert cli.command_of(argv) is None


def test_one_command_parses_as_the_whole_parser_does() -> None:
    argv = ["--log-level", "INFO", "walk", "--robot", "biped18-feetech", "--seconds", "3",
            "--set", "Slgt=0.9"]
    whole = vars(cli.build_parser().parse_args(argv))
    alone = vars(cli.build_parser(only=cli.command_of(argv)).parse_args(argv))
    assert alone == whole and whole["seconds"] == 3.0


def test_a_hardware_command_starts_without_the_simulator() -> None:
    code = ("import sys, robot.cli as c\n"
            f"for name in {HARDWARE!r}:\n"
            "    assert c.main([name, '--help']) == 0, name\n"
            "print(sorted(m for m in ('mujoco', 'pygltflib') if m in sys.modules))\n")
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "[]"
