"""What a plain install needs, checked fast: the wheel ships the bundled robots, gait presets
and panel files; robots and gaits load by bundled name or by path, user presets by name;
the sim bus comes from the ``biped.buses`` entry point; ``biped --version``.

(`make wheel-check` installs the wheel into a fresh venv and runs commands from outside the
checkout; this file covers what does not need a new venv.)
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from importlib.metadata import version
from pathlib import Path

import pytest

from robot.bus.base import Bus
from robot.bus.factory import ENTRY_POINT_GROUP, bus_kinds, make_bus, register_bus
from robot.cli import main
from robot.config.bundled import DEFAULT_ROBOT, GAITS_DIR, ROBOTS_DIR, gait_names, robot_names
from robot.config.gait_file import Gait, gait_to_toml, load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError

REPO = Path(__file__).resolve().parent.parent
#: What the distribution is built from (pyproject.toml's packages and readme).
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "robot", "sim")


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """A wheel built from a clean copy of the sources (a stale build/ directory in the
    checkout cannot add files to it), and what the build backend printed (pip -v)."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    for name in SOURCES:
        if (REPO / name).is_dir():
            shutil.copytree(REPO / name, src / name,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            src.mkdir(exist_ok=True)
            shutil.copy2(REPO / name, src / name)
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "-v", "--no-deps", str(src),
                        "-w", str(tmp / "dist")], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    (whl,) = (tmp / "dist").glob("biped-*.whl")
    return whl, r.stdout + r.stderr


@pytest.fixture(scope="module")
def wheel(built: tuple[Path, str]) -> Path:
    return built[0]


def test_the_licence_is_an_spdx_string_with_its_file_and_the_build_does_not_warn(
        built: tuple[Path, str]) -> None:
    """The packaging guide's form (core metadata 2.4): License-Expression and License-File;
    the TOML-table form made setuptools print a deprecation warning on every build."""
    whl, log = built
    assert "Warning" not in log and "deprecated" not in log, log
    with zipfile.ZipFile(whl) as z:
        (meta,) = [n for n in z.namelist() if n.endswith(".dist-info/METADATA")]
        text = z.read(meta).decode()
        assert any(n.endswith(".dist-info/licenses/LICENSE") for n in z.namelist())
    assert "License-Expression: MIT\n" in text and "License-File: LICENSE\n" in text
    assert (REPO / "LICENSE").read_text().startswith("MIT License")


@pytest.fixture(scope="module")
def wheel_files(wheel: Path) -> set[str]:
    with zipfile.ZipFile(wheel) as z:
        return set(z.namelist())


def test_wheel_ships_bundled_robots_and_presets(wheel_files: set[str]) -> None:
    for p in sorted(ROBOTS_DIR.glob("*.toml")) + sorted(GAITS_DIR.glob("*.toml")):
        assert f"robot/configs/{p.parent.name}/{p.name}" in wheel_files, p.name
    assert robot_names() and gait_names()


def test_wheel_ships_panel_static_files_and_typing_marker(wheel_files: set[str]) -> None:
    static = REPO / "robot" / "panel" / "static"
    for p in sorted(static.iterdir()):
        assert f"robot/panel/static/{p.name}" in wheel_files, p.name
    assert {"robot/py.typed", "sim/py.typed"} <= wheel_files


def test_wheel_declares_the_sim_bus_plugin_and_the_console_script(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as z:
        (name,) = [n for n in z.namelist() if n.endswith(".dist-info/entry_points.txt")]
        text = z.read(name).decode()
    assert f"[{ENTRY_POINT_GROUP}]\nsim = sim:open_bus" in text
    assert "[console_scripts]\nbiped = robot.cli:main" in text


def test_bundled_names_load() -> None:
    for name in robot_names():
        assert load_robot(name).source == str(ROBOTS_DIR / f"{name}.toml")
    for name in gait_names():
        assert load_gait(name).source == str(GAITS_DIR / f"{name}.toml")
    assert load_robot().source == str(DEFAULT_ROBOT)
    assert load_robot("biped18-feetech").bus.kind == "feetech"


def test_paths_still_load(tmp_path: Path) -> None:
    copy = tmp_path / "mine.toml"
    copy.write_text((ROBOTS_DIR / "biped18-feetech.toml").read_text())
    assert load_robot(str(copy)).bus.kind == "feetech"
    gait = tmp_path / "g.toml"
    gait.write_text((GAITS_DIR / "crouch.toml").read_text())
    assert load_gait(str(gait)).source == str(gait)


def test_unknown_names_list_the_valid_ones() -> None:
    with pytest.raises(ConfigError) as e:
        load_robot("biped99")
    msg = str(e.value)
    assert "--robot: unknown robot 'biped99'" in msg and "\n" not in msg
    assert all(n in msg for n in robot_names()) and "path" in msg
    with pytest.raises(ConfigError) as e:
        load_gait("moonwalk")
    msg = str(e.value)
    assert "--gait: unknown preset 'moonwalk'" in msg and "\n" not in msg
    assert all(n in msg for n in gait_names()) and "path" in msg


def test_a_missing_path_lists_the_bundled_names(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as e:
        load_robot("biped18-feetech.toml")   # a name given as a file name
    msg = str(e.value)
    assert msg.startswith("--robot biped18-feetech.toml: file not found") and "\n" not in msg
    assert all(n in msg for n in robot_names())
    with pytest.raises(ConfigError) as e:
        load_gait(str(tmp_path / "nowhere.toml"))
    msg = str(e.value)
    assert "nowhere.toml: file not found" in msg and all(n in msg for n in gait_names())


def test_gait_name_finds_a_user_preset_after_the_bundled_ones(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    user = tmp_path / "biped" / "gaits"
    user.mkdir(parents=True)
    fast = load_gait("walk").params.replace({"vM": 0.5})
    (user / "brisk.toml").write_text(gait_to_toml(Gait("brisk", fast)))
    # A user file named like a bundled preset never shadows it.
    (user / "walk.toml").write_text(gait_to_toml(Gait("walk", fast)))
    assert load_gait("brisk").source == str(user / "brisk.toml")
    assert load_gait("brisk").params.vM == 0.5
    assert load_gait("walk").source == str(GAITS_DIR / "walk.toml")
    with pytest.raises(ConfigError, match=rf"saved in {user}: brisk; or a path"):
        load_gait("nope")


def test_unknown_bus_lists_the_kinds() -> None:
    robot = load_robot()
    with pytest.raises(ConfigError) as e:
        make_bus("can", robot=robot)
    assert "--bus: unknown bus 'can'; valid: sim, dynamixel, dynamixel1, feetech" in str(e.value)
    assert ENTRY_POINT_GROUP in str(e.value)


def test_sim_bus_comes_from_the_entry_point() -> None:
    bus = make_bus("sim", robot=load_robot())
    assert type(bus).__module__ == "sim.mujoco.bus"
    source = (REPO / "robot" / "bus" / "factory.py").read_text()
    assert "import sim" not in source and "from sim" not in source


def test_register_bus_adds_a_kind(monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[tuple[RobotConfig, str | None]] = []

    def fake(robot: RobotConfig, *, port: str | None, baud: int | None, **options: object) -> Bus:
        made.append((robot, port))
        return make_bus("sim", robot=robot)

    monkeypatch.setattr("robot.bus.factory._registered", {})
    register_bus("loopback", fake)
    assert "loopback" in bus_kinds()
    robot = load_robot()
    make_bus("loopback", robot=robot, port="x")
    assert made == [(robot, "x")]
    with pytest.raises(ConfigError, match="built-in bus kind"):
        register_bus("dynamixel", fake)


def test_version_is_the_installed_one(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"biped {version('biped')}"
