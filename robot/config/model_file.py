"""A robot file's ``[model]`` table ↔ ``BodyModel`` (robot/body/model.py).

Written by ``biped robots import`` (``model_toml``), read by robot/config/robot_file.py
(``parse_model``): every problem is one line naming the file, the field and what was
found. Numbers are written with 9 significant digits (a nanometre on a metre).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from robot.body.legs import ORDERS, LegChain
from robot.body.model import BodyModel
from robot.body.tree import SHAPE_KINDS, BodyTree, Frame, Hinge, Inertial, Link, Shape
from robot.config.toml_io import TomlValue, show
from robot.errors import ConfigError

LEG_KEYS = ("hip", "thigh", "shin", "sole", "yaw_axis", "roll_drop", "lateral", "ankle_drop",
            "has_ankle_roll", "order", "knee_back")


def num(v: float) -> str:
    return repr(0.0) if v == 0 else f"{v:.9g}" if "e" in f"{v:.9g}" or "." in f"{v:.9g}" \
        else f"{v:.9g}.0"


def vec(values: tuple[float, ...] | list[float]) -> str:
    return "[" + ", ".join(num(float(v)) for v in values) + "]"


def _q(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def model_toml(model: BodyModel) -> str:
    """The ``[model]`` tables of ``model`` as TOML text."""
    t = model.tree
    out = ["[model]",
           f"file = {_q(model.file)}", f"source = {_q(model.source)}",
           f"licence = {_q(model.licence)}",
           "# the robot's x (forward), y (left), z (up) in the model's root frame",
           f"axes = [{', '.join(vec(a) for a in model.axes)}]",
           "# the pelvis origin (midway between the hips' pitch axes) in the root frame [m]",
           f"pelvis = {vec(model.pelvis)}",
           "excludes = [" + ", ".join(f"[{_q(a)}, {_q(b)}]" for a, b in t.excludes) + "]", ""]
    for leg in model.legs:
        out += [f"[model.legs.{leg.side}]  # the leg as the IK solves it (pelvis frame, zero pose) [m]",
                f"hip = {vec(leg.hip)}", f"thigh = {num(leg.thigh)}", f"shin = {num(leg.shin)}",
                f"sole = {vec(leg.sole)}"]
        if leg.yaw_axis is not None:
            out.append(f"yaw_axis = {vec(leg.yaw_axis)}")
        out += [f"roll_drop = {num(leg.roll_drop)}", f"lateral = {num(leg.lateral)}",
                f"ankle_drop = {num(leg.ankle_drop)}",
                f"has_ankle_roll = {'true' if leg.has_ankle_roll else 'false'}",
                f"order = {_q(leg.order)}",
                f"knee_back = {'true' if leg.knee_back else 'false'}  # true: the knee bends "
                "backward (knee angles <= 0)", ""]
    for link in t.links:
        out += ["[[model.links]]", f"name = {_q(link.name)}",
                f"parent = {_q(t.links[link.parent].name if link.parent >= 0 else '')}",
                f"pos = {vec(link.pos)}", f"quat = {vec(link.quat)}"]
        if link.inertial is not None:
            i = link.inertial
            out += [f"mass = {num(i.mass)}", f"com = {vec(i.com)}",
                    f"inertia = {vec(i.inertia)}  # ixx iyy izz ixy ixz iyz [kg m^2]"]
        if link.joint is not None:
            j = link.joint
            out += [f"joint = {_q(j.name)}", f"axis = {vec(j.axis)}", f"anchor = {vec(j.pos)}"]
            if j.range is not None:
                out.append(f"range = {vec(j.range)}")
            if j.effort is not None:
                out.append(f"effort = {num(j.effort)}")
            if j.velocity is not None:
                out.append(f"velocity = {num(j.velocity)}")
        for s in link.shapes:
            out += ["[[model.links.shapes]]", f"kind = {_q(s.kind)}", f"pos = {vec(s.pos)}",
                    f"quat = {vec(s.quat)}"]
            if s.size:
                out.append(f"size = {vec(s.size)}")
            if s.vertices:
                out.append("vertices = [" + ", ".join(vec(v) for v in s.vertices) + "]")
            if s.note:
                out.append(f"note = {_q(s.note)}")
        for f in link.frames:
            out += ["[[model.links.frames]]", f"name = {_q(f.name)}", f"pos = {vec(f.pos)}",
                    f"quat = {vec(f.quat)}"]
        out.append("")
    return "\n".join(out)


# ---------------------------------------------------------------------- reading


def _get(src: str, path: str, tab: Mapping[str, TomlValue], key: str,
         default: TomlValue | None = None) -> TomlValue:
    if key in tab:
        return tab[key]
    if default is None:
        raise ConfigError(f"{src}: {path}.{key}: missing")
    return default


def _floats(src: str, path: str, value: TomlValue, n: int | None) -> tuple[float, ...]:
    if not isinstance(value, list) or (n is not None and len(value) != n) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value):
        want = f"{n} finite numbers" if n is not None else "finite numbers"
        raise ConfigError(f"{src}: {path}: expected a list of {want}, got {show(value)}")
    return tuple(float(v) for v in value)  # type: ignore[arg-type]


def _number(src: str, path: str, value: TomlValue, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
            or (positive and value <= 0):
        raise ConfigError(f"{src}: {path}: expected a finite number{' > 0' if positive else ''}, "
                          f"got {show(value)}")
    return float(value)


def _text(src: str, path: str, value: TomlValue) -> str:
    if not isinstance(value, str):
        raise ConfigError(f"{src}: {path}: expected a string, got {show(value)}")
    return value


def _table(src: str, path: str, value: TomlValue) -> Mapping[str, TomlValue]:
    if not isinstance(value, dict):
        raise ConfigError(f"{src}: {path}: expected a table, got {show(value)}")
    return value


def _shape(src: str, path: str, tab: Mapping[str, TomlValue]) -> Shape:
    kind = _text(src, f"{path}.kind", _get(src, path, tab, "kind"))
    if kind not in SHAPE_KINDS:
        raise ConfigError(f"{src}: {path}.kind: expected one of {', '.join(SHAPE_KINDS)}, got {kind!r}")
    size = _floats(src, f"{path}.size", tab.get("size", []), None)
    if any(v <= 0 for v in size):
        raise ConfigError(f"{src}: {path}.size: every size must be > 0, got {list(size)}")
    verts = tab.get("vertices", [])
    if not isinstance(verts, list):
        raise ConfigError(f"{src}: {path}.vertices: expected a list of [x, y, z]")
    vertices = tuple(_floats(src, f"{path}.vertices[{k}]", v, 3) for k, v in enumerate(verts))
    need = {"box": 3, "sphere": 1, "capsule": 2, "cylinder": 2, "hull": 0}[kind]
    if len(size) != need or (kind == "hull" and len(vertices) < 4):
        what = "at least 4 vertices" if kind == "hull" else f"{need} sizes"
        raise ConfigError(f"{src}: {path}: a {kind} needs {what}")
    return Shape(kind, _floats(src, f"{path}.pos", tab.get("pos", [0, 0, 0]), 3),  # type: ignore[arg-type]
                 _floats(src, f"{path}.quat", tab.get("quat", [1, 0, 0, 0]), 4),  # type: ignore[arg-type]
                 size, vertices, note=_text(src, f"{path}.note", tab.get("note", "")))  # type: ignore[arg-type]


def _link(src: str, path: str, tab: Mapping[str, TomlValue], index: dict[str, int]) -> Link:
    name = _text(src, f"{path}.name", _get(src, path, tab, "name"))
    parent_name = _text(src, f"{path}.parent", _get(src, path, tab, "parent"))
    if name in index:
        raise ConfigError(f"{src}: {path}.name: link {name!r} appears twice")
    if (parent_name == "") != (not index):
        raise ConfigError(f"{src}: {path}.parent: only the first link is the root (parent \"\")")
    if parent_name and parent_name not in index:
        raise ConfigError(f"{src}: {path}.parent: {parent_name!r} is not a link listed before it")
    inertial = None
    if "mass" in tab:
        inertial = Inertial(_number(src, f"{path}.mass", tab["mass"], positive=True),
                            _floats(src, f"{path}.com", _get(src, path, tab, "com"), 3),  # type: ignore[arg-type]
                            _floats(src, f"{path}.inertia", _get(src, path, tab, "inertia"), 6))  # type: ignore[arg-type]
    joint = None
    if "joint" in tab:
        rng = _floats(src, f"{path}.range", tab["range"], 2) if "range" in tab else None
        if rng is not None and not rng[0] < rng[1]:
            raise ConfigError(f"{src}: {path}.range: expected [lo, hi] with lo < hi, got {list(rng)}")
        axis = _floats(src, f"{path}.axis", _get(src, path, tab, "axis"), 3)
        if math.hypot(*axis) < 1e-9:
            raise ConfigError(f"{src}: {path}.axis: a zero vector")
        joint = Hinge(_text(src, f"{path}.joint", tab["joint"]), axis,  # type: ignore[arg-type]
                      _floats(src, f"{path}.anchor", tab.get("anchor", [0, 0, 0]), 3),  # type: ignore[arg-type]
                      rng,  # type: ignore[arg-type]
                      _number(src, f"{path}.effort", tab["effort"], positive=True)
                      if "effort" in tab else None,
                      _number(src, f"{path}.velocity", tab["velocity"], positive=True)
                      if "velocity" in tab else None)
    shapes = tab.get("shapes", [])
    frames = tab.get("frames", [])
    if not isinstance(shapes, list) or not isinstance(frames, list):
        raise ConfigError(f"{src}: {path}: shapes and frames must be arrays of tables")
    return Link(name, index[parent_name] if parent_name else -1,
                _floats(src, f"{path}.pos", tab.get("pos", [0, 0, 0]), 3),  # type: ignore[arg-type]
                _floats(src, f"{path}.quat", tab.get("quat", [1, 0, 0, 0]), 4),  # type: ignore[arg-type]
                inertial, joint,
                tuple(_shape(src, f"{path}.shapes[{k}]", _table(src, f"{path}.shapes[{k}]", s))
                      for k, s in enumerate(shapes)),
                tuple(_frame(src, f"{path}.frames[{k}]", f) for k, f in enumerate(frames)))


def _frame(src: str, path: str, value: TomlValue) -> Frame:
    tab = _table(src, path, value)
    return Frame(_text(src, f"{path}.name", _get(src, path, tab, "name")),
                 _floats(src, f"{path}.pos", tab.get("pos", [0, 0, 0]), 3),  # type: ignore[arg-type]
                 _floats(src, f"{path}.quat", tab.get("quat", [1, 0, 0, 0]), 4))  # type: ignore[arg-type]


def _leg(src: str, side: str, tab: Mapping[str, TomlValue]) -> LegChain:
    path = f"model.legs.{side}"
    unknown = sorted(set(tab) - set(LEG_KEYS))
    if unknown:
        raise ConfigError(f"{src}: {path}.{unknown[0]}: unknown key; valid: {', '.join(LEG_KEYS)}")
    order = _text(src, f"{path}.order", tab.get("order", "yaw_roll"))
    if order not in ORDERS:
        raise ConfigError(f"{src}: {path}.order: expected one of {', '.join(ORDERS)}, got {order!r}")
    roll = tab.get("has_ankle_roll", True)
    if not isinstance(roll, bool):
        raise ConfigError(f"{src}: {path}.has_ankle_roll: expected true or false, got {show(roll)}")
    back = tab.get("knee_back", False)
    if not isinstance(back, bool):
        raise ConfigError(f"{src}: {path}.knee_back: expected true or false, got {show(back)}")
    return LegChain(side, _floats(src, f"{path}.hip", _get(src, path, tab, "hip"), 3),  # type: ignore[arg-type]
                    _number(src, f"{path}.thigh", _get(src, path, tab, "thigh"), positive=True),
                    _number(src, f"{path}.shin", _get(src, path, tab, "shin"), positive=True),
                    _floats(src, f"{path}.sole", _get(src, path, tab, "sole"), 3),  # type: ignore[arg-type]
                    _floats(src, f"{path}.yaw_axis", tab["yaw_axis"], 2) if "yaw_axis" in tab else None,  # type: ignore[arg-type]
                    _number(src, f"{path}.roll_drop", tab.get("roll_drop", 0.0)),
                    _number(src, f"{path}.lateral", tab.get("lateral", 0.0)),
                    _number(src, f"{path}.ankle_drop", tab.get("ankle_drop", 0.0)), roll, order,
                    back)


def parse_model(src: str, value: TomlValue) -> BodyModel:
    """A robot file's ``[model]`` table as a BodyModel (one-line ConfigError on any fault)."""
    tab = _table(src, "model", value)
    allowed = {"file", "source", "licence", "axes", "pelvis", "excludes", "legs", "links"}
    unknown = sorted(set(tab) - allowed)
    if unknown:
        raise ConfigError(f"{src}: model.{unknown[0]}: unknown key; valid: {', '.join(sorted(allowed))}")
    links_raw = _get(src, "model", tab, "links")
    if not isinstance(links_raw, list) or not links_raw:
        raise ConfigError(f"{src}: model.links: expected an array of link tables")
    index: dict[str, int] = {}
    links = []
    for k, raw in enumerate(links_raw):
        link = _link(src, f"model.links[{k}]", _table(src, f"model.links[{k}]", raw), index)
        index[link.name] = k
        links.append(link)
    excludes = []
    pairs = tab.get("excludes", [])
    if not isinstance(pairs, list):
        raise ConfigError(f"{src}: model.excludes: expected a list of [link, link] pairs")
    for k, pair in enumerate(pairs):
        if not (isinstance(pair, list) and len(pair) == 2 and all(p in index for p in pair)):
            raise ConfigError(f"{src}: model.excludes[{k}]: expected two link names, got {show(pair)}")
        excludes.append((str(pair[0]), str(pair[1])))
    axes_raw = _get(src, "model", tab, "axes")
    if not isinstance(axes_raw, list) or len(axes_raw) != 3:
        raise ConfigError(f"{src}: model.axes: expected three [x, y, z] rows, got {show(axes_raw)}")
    axes = tuple(_floats(src, f"model.axes[{k}]", a, 3) for k, a in enumerate(axes_raw))
    legs_tab = _table(src, "model.legs", _get(src, "model", tab, "legs"))
    legs = tuple(_leg(src, s, _table(src, f"model.legs.{s}", _get(src, "model.legs", legs_tab, s)))
                 for s in "rl")
    tree = BodyTree(tuple(links), source=src, excludes=tuple(excludes))
    return BodyModel(tree, axes, _floats(src, "model.pelvis", _get(src, "model", tab, "pelvis"), 3),  # type: ignore[arg-type]
                     (legs[0], legs[1]), _text(src, "model.file", tab.get("file", "")),
                     _text(src, "model.source", tab.get("source", "")),
                     _text(src, "model.licence", tab.get("licence", "")))
