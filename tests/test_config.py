"""Robot and gait files: every error is one line naming the file, the field and what is
expected; GaitParams.replace validates; gait_to_toml round-trips."""

from __future__ import annotations

import copy
import dataclasses
import math
import re
import tomllib
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.bus.limits import TickLimits
from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR, gait_names
from robot.config.gait_file import Gait, gait_to_toml, load_gait, parse_gait
from robot.config.joint_names import ARM_NAMES
from robot.config.params import ALIASES, SPECS, GaitParams
from robot.config.robot_file import load_robot, parse_robot
from robot.errors import BipedError, BusError, ConfigError

BASE_ROBOT = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
BASE = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")


def load_error(loader: Callable[[Path], object], path: Path, text: str) -> str:
    """Write ``text`` to ``path``, load it and return the one-line ConfigError message."""
    path.write_text(text)
    with pytest.raises(ConfigError) as info:
        loader(path)
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: "), msg
    return msg


def robot_error(tmp_path: Path, edit: Callable[[str], str]) -> str:
    text = edit(BASE_ROBOT)
    assert text != BASE_ROBOT, "the edit did not apply"
    return load_error(load_robot, tmp_path / "broken-robot.toml", text)


def gait_error(tmp_path: Path, text: str) -> str:
    return load_error(load_gait, tmp_path / "broken-gait.toml", text)


def sub(old: str, new: str, count: int = 1) -> Callable[[str], str]:
    return lambda text: text.replace(old, new, count)


def drop_joint(name: str) -> Callable[[str], str]:
    return lambda text: re.sub(rf"\[joints\.{name}\][^\[]*", "", text)


def joint_field(joint: str, field: str, value: str) -> Callable[[str], str]:
    """Set ``field`` of ``[joints.<joint>]`` to the TOML literal ``value``."""
    def edit(text: str) -> str:
        head = f"[joints.{joint}]\n"
        i = text.index(head)
        j = text.index("\n\n", i)
        block = re.sub(rf"^{field} = .*$", f"{field} = {value}", text[i:j], flags=re.M)
        return text[:i] + block + text[j:]
    return edit


# ----------------------------------------------------------------------------- robots


def test_bundled_robots_load() -> None:
    for path in sorted(ROBOTS_DIR.glob("*.toml")):
        r = load_robot(path)
        legs = 2 * (4 + r.has_hip_yaw + r.has_ankle_roll)   # 5-DoF legs: no yaw or ankle roll
        extras = sum(j.fixed_rad is not None for j in r.joints)   # a kit's neck and head
        n = legs + (6 if r.has_arms else 0) + extras
        assert len(r.joints) == n and len(set(r.ids)) == n
        assert r.source == str(path)
    assert len(load_robot(ROBOTS_DIR / "robotis-mini.toml").ids) == 16   # its 16 XL-320s


@pytest.mark.parametrize("edit, expect", [
    (sub("thigh = 0.11 ", ""), "geometry.thigh: missing"),
    (sub('name = "biped18-dynamixel"\n', ""), "name: missing"),
    (sub("[mass]", "[masses]"), "masses: unknown key"),
    (sub("baud = 1000000", 'baud = "fast"'), "bus.baud: expected an integer, got 'fast'"),
    (sub("thigh = 0.11", 'thigh = "long"'), "geometry.thigh: expected a number in [0.001, 2] m, got 'long'"),
    (joint_field("r_knee", "servo_id", "4.5"), "joints.r_knee.servo_id: expected an integer"),
    (sub("thigh = 0.11", "thigh = -0.11"),
     "geometry.thigh: expected a number in [0.001, 2] m, got -0.11"),
    (lambda t: "colour = 'red'\n" + t, "colour: unknown key; valid: balance, bus, gait, geometry"),
    (sub("[bus]\n", "[bus]\nparity = 'N'\n"), "bus.parity: unknown key; valid: kind, model"),
    (sub("[joints.r_knee]\n", "[joints.r_knee]\noffset = 3\n"),
     "joints.r_knee.offset: unknown key; valid: servo_id, sign"),
    (sub("[joints.r_knee]", "[joints.r_kneecap]"), "joints.r_kneecap: unknown joint; the gait drives"),
    (lambda t: joint_field("r_knee", "max_rad", "0.0")(
        joint_field("r_knee", "min_rad", "2.3")(t)),
     "joints.r_knee: limits reversed or empty: min_rad 2.3 must be < max_rad 0.0"),
    (joint_field("r_knee", "max_rad", "4.0"),
     "joints.r_knee.max_rad: expected a number in [-pi, pi] rad, got 4.0"),
    (joint_field("l_knee", "servo_id", "4"),
     "joints.l_knee.servo_id: duplicate servo id 4 (also joints.r_knee)"),
    (joint_field("l_knee", "servo_id", "300"),
     "joints.l_knee.servo_id: expected an integer in [0, 252], got 300"),
    (joint_field("l_hip_yaw", "sign", "2"), "joints.l_hip_yaw.sign: expected +1 or -1, got 2"),
    (joint_field("r_knee", "zero_ticks", "4096"),
     "joints.r_knee.zero_ticks: expected an integer in [0, 4095]"),
    (joint_field("r_knee", "max_speed_rad_s", "0.0"),
     "joints.r_knee.max_speed_rad_s: expected a number in [0.05, 20] rad/s, got 0.0"),
    (sub("thigh = 0.11", "thigh = nan"), "geometry.thigh: expected a finite number in [0.001, 2] m, got nan"),
    (joint_field("r_knee", "max_rad", "nan"), "joints.r_knee.max_rad: expected a finite number"),
    (sub("thigh = 0.11", "thigh = inf"), "geometry.thigh: expected a finite number in [0.001, 2] m, got inf"),
    (sub('model = "XL430-W250"', 'model = "XL999"'),
     "bus.model: unknown servo model 'XL999'; valid: XL430-W250"),
    (sub('kind = "dynamixel"', 'kind = "feetech"'),
     "bus.model: XL430-W250 is not a feetech servo"),
    (sub('kind = "dynamixel"', 'kind = "can"'), "bus.kind: expected one of dynamixel, dynamixel1, feetech"),
    (drop_joint("l_elbow"), "joints.l_elbow: missing (arms need all of"),
    (drop_joint("r_ankle_roll"), "joints.r_ankle_roll: missing (ankle roll on both legs, or neither"),
    (sub("r_knee = 1.1", "r_knee = 2.9"), "rest.r_knee: 2.9 is outside the joint limits"),
    (sub("r_knee = 1.1", "r_toe = 1.1"), "rest.r_toe: unknown joint"),
    (sub('name = "biped18-dynamixel"', "name = 42"), "name: expected a non-empty string, got 42"),
])
def test_robot_errors_name_file_field_and_expectation(tmp_path: Path,
                                                      edit: Callable[[str], str],
                                                      expect: str) -> None:
    msg = robot_error(tmp_path, edit)
    assert expect in msg, msg


def test_robot_without_arms_is_valid(tmp_path: Path) -> None:
    text = BASE_ROBOT.split("[rest]")[0]
    for name in ARM_NAMES:
        text = drop_joint(name)(text)
    path = tmp_path / "legs.toml"
    path.write_text(text)
    robot = load_robot(path)
    assert not robot.has_arms and len(robot.joints) == 12


def test_robot_file_problems_are_config_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"nowhere\.toml: file not found"):
        load_robot(tmp_path / "nowhere.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("name = [unclosed\n")
    with pytest.raises(ConfigError, match=r"bad\.toml: not valid TOML"):
        load_robot(bad)
    assert issubclass(ConfigError, BipedError)


# ----------------------------------------------------------------------------- gaits


@pytest.mark.parametrize("text, expect", [
    ("[params]\nvM = 5.0\n", "params.vM: vM = 5.0 is outside [0, 2] rad/frame"),
    ("[params]\nSlgt_R = -0.1\n", "params.Slgt_R: Slgt_R = -0.1 is outside [0, 3]"),
    ("[mapping]\nsway = 0.5\n", "mapping.sway: sway = 0.5 is outside [0, 0.06] m"),
    ("fps = 1000.0\n", "fps: fps = 1000.0 is outside [1, 240] frame/s"),
    ("[params]\nvM = nan\n", "params.vM: vM = nan is outside [0, 2]"),
    ("[params]\nomegaB = inf\n", "params.omegaB: omegaB = inf is outside"),
    ("fps = nan\n", "fps: fps = nan is outside"),
    ("[params]\nvM = 'fast'\n", "params.vM: vM must be a number in [0, 2] rad/frame, got 'fast'"),
    ("[params]\nvM = true\n", "params.vM: vM must be a number"),
    ("[params]\nfoo = 1.0\n", "params.foo: unknown gait parameter 'foo'; valid: fps, vM"),
    ("[params]\nsway = 0.01\n", "params.sway: sway belongs in [mapping]"),
    ("[mapping]\nvM = 0.3\n", "mapping.vM: vM belongs in [params]"),
    ("[params]\nfps = 30.0\n", "params.fps: fps belongs at the top level"),
    ("speed = 1.0\n", "speed: unknown key; valid: description, fps, mapping, name, params"),
    ("[params]\nWpos_R = 0.5\nApos_R = 0.5\n", "Apos_R given twice"),
    ("params = 3\n", "params: expected a table, got 3"),
    ("name = ''\n", "name: expected a non-empty string"),
])
def test_gait_errors_name_file_field_and_expectation(tmp_path: Path, text: str,
                                                     expect: str) -> None:
    msg = gait_error(tmp_path, text)
    assert expect in msg, msg


def test_unknown_preset_lists_the_valid_ones() -> None:
    with pytest.raises(ConfigError) as info:
        load_gait("sprint")
    msg = str(info.value)
    assert "'sprint'" in msg and "\n" not in msg
    names = gait_names()
    assert {"walk", "march", "crouch", "high_step", "paper"} <= set(names)
    assert ", ".join(names) in msg


def test_presets_load_by_name_with_their_names() -> None:
    for name in gait_names():
        g = load_gait(name)
        assert g.name == name and g.source.endswith(f"{name}.toml")
    assert load_gait().name == "walk"


def test_arm_aliases_are_accepted(tmp_path: Path) -> None:
    path = tmp_path / "alias.toml"
    path.write_text("[params]\nWpos_R = 0.5\nWpos_L = -0.5\nWhgt_R = 1.5\nWhgt_L = 2.0\n"
                    "Wosc_R = 0.3\nWosc_L = 0.4\n")
    p = load_gait(path).params
    assert (p.Apos_R, p.Apos_L, p.Ahgt_R, p.Ahgt_L, p.Aosc_R, p.Aosc_L) == \
        (0.5, -0.5, 1.5, 2.0, 0.3, 0.4)
    assert set(ALIASES.values()) <= set(SPECS)
    assert GaitParams().replace({"Wosc_L": 0.7}).Aosc_L == 0.7


def test_missing_gait_params_take_their_defaults(tmp_path: Path) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text("[params]\nvM = 0.4\n")
    g = load_gait(path)
    assert g.name == "tiny"
    assert g.params == GaitParams(vM=0.4)
    assert all(getattr(GaitParams(), n) == s.default for n, s in SPECS.items())


params_st = st.fixed_dictionaries({
    n: st.floats(s.lo, s.hi, allow_nan=False) for n, s in SPECS.items()})
names_st = st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=20)


@settings(max_examples=150, deadline=None)
@given(names_st, params_st)
def test_gait_to_toml_round_trips(name: str, values: dict[str, float]) -> None:
    gait = Gait(name=name, params=GaitParams(**values))
    back = parse_gait(tomllib.loads(gait_to_toml(gait)), source="roundtrip.toml")
    assert back.name == name
    assert back.params == gait.params


def test_presets_round_trip_through_toml(tmp_path: Path) -> None:
    for name in gait_names():
        gait = load_gait(name)
        path = tmp_path / f"{name}-copy.toml"
        path.write_text(gait_to_toml(gait))
        assert load_gait(path).params == gait.params


# ----------------------------------------------------------------------------- replace


BAD_VALUES = [
    ("vM", 2.5), ("vM", -0.01), ("Fhgt_R", 3.0001), ("sway", -1e-9), ("vM", math.nan),
    ("vM", math.inf), ("fps", -math.inf), ("vM", "0.3"), ("vM", True), ("stance", False),
    ("vM", None), ("vM", [0.3]), ("vMax", 0.3), ("Wfoo", 1.0),
]


@pytest.mark.parametrize("name, value", BAD_VALUES)
def test_replace_refuses_bad_values_and_changes_nothing(name: str, value: object) -> None:
    p = GaitParams(vM=0.3, stance=0.9)
    before = dataclasses.asdict(p)
    with pytest.raises(ConfigError) as info:
        # A good change alongside the bad one must not be applied either.
        p.replace({"Slgt_R": 1.0, name: value}, where="panel")
    msg = str(info.value)
    assert msg.startswith("panel: ") and "\n" not in msg
    assert (name if name in SPECS else repr(name)) in msg
    assert dataclasses.asdict(p) == before


@settings(max_examples=100, deadline=None)
@given(st.sampled_from(sorted(SPECS)), st.floats(allow_nan=True))
def test_replace_accepts_exactly_the_spec_range(name: str, value: float) -> None:
    spec = SPECS[name]
    p = GaitParams()
    if math.isfinite(value) and spec.lo <= value <= spec.hi:
        assert getattr(p.replace({name: value}), name) == value
    else:
        with pytest.raises(ConfigError, match=name):
            p.replace({name: value})
    assert p == GaitParams()


def test_replace_accepts_ints_and_bounds() -> None:
    p = GaitParams().replace({"vM": 1, "Slgt_R": SPECS["Slgt_R"].hi, "turn": SPECS["turn"].lo})
    assert p.vM == 1.0 and isinstance(p.vM, float)
    assert p.Slgt_R == SPECS["Slgt_R"].hi and p.turn == SPECS["turn"].lo


# ----------------------------------------------------------------------------- ticks
# ServoMap: ticks = zero_ticks + sign * q * 4096 / (2 pi); the bus accepts 0..4095.
# By hand: 2047 ticks above 2048 is 2047 * 2 pi / 4096 = 3.14006 rad; 100 ticks below
# is -0.15340 rad (-0.1533 rounded inward); 195 ticks above 3900 with sign -1 is -0.29913 rad.


@pytest.mark.parametrize("edits, expect", [
    ([("r_knee", "max_rad", "3.141592653589793")],
     "joints.r_knee.max_rad: 3.14159 rad is tick 4096, outside the servo's 0..4095 "
     "(zero_ticks 2048, sign +1); expected min_rad and max_rad within [-3.1415, 3.1400] rad"),
    ([("r_hip_yaw", "zero_ticks", "100")],
     "joints.r_hip_yaw.min_rad: -0.6 rad is tick -291, outside the servo's 0..4095 "
     "(zero_ticks 100, sign +1); expected min_rad and max_rad within [-0.1533, 3.1415] rad"),
    ([("l_hip_yaw", "zero_ticks", "3900")],
     "joints.l_hip_yaw.min_rad: -0.6 rad is tick 4291, outside the servo's 0..4095 "
     "(zero_ticks 3900, sign -1); expected min_rad and max_rad within [-0.2991, 3.1415] rad"),
    ([("r_hip_yaw", "min_rad", "0.0001"), ("r_hip_yaw", "max_rad", "0.0002")],
     "joints.r_hip_yaw.min_rad/max_rad: [0.0001, 0.0002] rad holds no whole servo tick; "
     "expected limits at least one tick (0.00153 rad) apart"),
])
def test_limits_the_bus_would_refuse_are_refused_at_load(
        tmp_path: Path, edits: list[tuple[str, str, str]], expect: str) -> None:
    def edit(text: str) -> str:
        for joint, field, value in edits:
            text = joint_field(joint, field, value)(text)
        return text
    msg = robot_error(tmp_path, edit)
    assert expect in msg, msg


@pytest.mark.parametrize("joint, zero, lo, hi", [
    ("r_knee", "2048", "-3.1415", "3.1400"),
    ("r_hip_yaw", "100", "-0.1533", "3.1415"),
    ("l_hip_yaw", "3900", "-0.2991", "3.1415"),
])
def test_the_range_a_message_names_loads(tmp_path: Path, joint: str, zero: str, lo: str,
                                         hi: str) -> None:
    text = BASE_ROBOT
    for field, value in (("zero_ticks", zero), ("min_rad", lo), ("max_rad", hi)):
        text = joint_field(joint, field, value)(text)
    path = tmp_path / "fits.toml"
    path.write_text(text.split("[rest]")[0])
    j = load_robot(path).joint(joint)
    assert (j.min_rad, j.max_rad) == (float(lo), float(hi))


BASE_DATA = tomllib.loads(BASE_ROBOT)
JOINT = "r_hip_yaw"  # no [rest] entry, so any limits are consistent with the rest pose
ANGLES = [-math.inf, -1e300, -math.pi, -1.0, 0.0, 1.0, math.pi, 1e300, math.inf]


@settings(max_examples=300, deadline=None)
@given(zero=st.integers(0, 4095), sign=st.sampled_from([1, -1]),
       ends=st.lists(st.floats(-math.pi, math.pi), min_size=2, max_size=2, unique=True),
       extra=st.lists(st.floats(allow_nan=False), max_size=5))
def test_a_config_loads_iff_the_bus_accepts_every_goal(zero: int, sign: int,
                                                       ends: list[float],
                                                       extra: list[float]) -> None:
    lo, hi = sorted(ends)
    data = copy.deepcopy(BASE_DATA)
    data["joints"][JOINT].update(zero_ticks=zero, sign=sign, min_rad=lo, max_rad=hi)
    i = [j.name for j in BASE.joints].index(JOINT)
    probe = [*ANGLES, lo, hi, *extra]
    try:
        robot = parse_robot(data, source="prop.toml")
    except ConfigError as e:
        assert re.match(rf"prop.toml: joints.{JOINT}.(min_rad|max_rad)", str(e)), e
        # The same joint, unchecked: some angle's goal is refused by the bus.
        joints = list(BASE.joints)
        joints[i] = dataclasses.replace(joints[i], zero_ticks=zero, sign=sign, min_rad=lo,
                                        max_rad=hi)
        raw = dataclasses.replace(BASE, joints=tuple(joints))
        sm, limits, refused = ServoMap(raw), TickLimits(raw), 0
        for q in probe:
            sid, t = list(sm.goals([*[0.0] * i, q, *[0.0] * (len(joints) - i - 1)]).items())[i]
            try:
                limits.check(sid, t)
            except BusError:
                refused += 1
        assert refused > 0
        return
    sm, limits = ServoMap(robot), TickLimits(robot)
    for q in probe:
        for sid, t in sm.goals([q] * len(robot.joints)).items():
            assert limits.check(sid, t) == t
        assert (0 <= sm.to_ticks([q] * len(robot.joints))).all()
        assert (sm.to_ticks([q] * len(robot.joints)) <= 4095).all()
