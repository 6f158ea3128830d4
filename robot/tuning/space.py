"""What `biped tune` searches: gait and balance parameters with ranges.

A ``Knob`` is one searched value; it may drive a pair of parameters (``Slgt`` sets
``Slgt_R`` and ``Slgt_L``: a walk stays symmetric and the search has half the
dimensions). Ranges default to the preset's value x [1 - SPAN, 1 + SPAN], inside the
parameter's documented range (robot/config/params.py SPECS); a parameter the preset leaves at 0
gets SPAN of its documented span around 0. ``--param NAME=LO:HI`` sets one by hand.

``DEFAULT_KNOBS`` are the ones that matter, from the sensitivity study in docs/tuning.md
(`biped tune --sensitivity`): the parameters whose +-20 % change moved the robustness
score most on the bundled robots, and the balance gains the stepping depends on.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import NamedTuple

from robot.config.params import ALIASES, SPECS, GaitParams
from robot.errors import ConfigError

#: Default half-width of a knob's range, as a share of the preset's value.
SPAN = 0.5
#: Pairs searched as one knob: NAME -> (NAME_R, NAME_L).
PAIRS = {n[:-2]: (n, n[:-2] + "_L") for n in SPECS if n.endswith("_R")
         and n[:-2] + "_L" in SPECS}
#: The default search (docs/tuning.md, "Sensitivity"): the knobs whose +-20 % moved the
#: quick suite's score most on the Dynamixel robot (Slgt 1.15, sway 1.11, delta_f 1.02,
#: vM 0.91, stance 0.83, bal_ankle_pd 0.08, bal_brace_xi 0.07, Fhgt 0.03); hip damping and
#: ankle stiffness moved it more, but only down from 0, so they stay off.
DEFAULT_KNOBS = ("vM", "Slgt", "Fhgt", "sway", "stance", "delta_f", "bal_ankle_pd",
                 "bal_brace_xi")
#: Added to the default search on 5-DoF legs (no hip yaw): the heading loop steers them by
#: step length, and which way a longer right stride turns the body depends on the robot
#: and the gait (in MuJoCo the 5-DoF AX-12 robot turns with it in `walk`, against it in a
#: deep crouch with long strides), so its sign and gain and the trim's size are searched
#: with the walk (issue 22: without them the tuned preset crossed 3 mm bumps at 0.050 to
#: 0.106 m/s, turning 20-70 deg; with them at 0.088 to 0.115, target 0.110).
FIVE_DOF_KNOBS = ("bal_stride_turn=-1:1", "bal_turn_max=0:0.1")
#: Never searched: they are commands or units, not properties of a good walk.
FIXED = frozenset({"fps", "speed", "turn", "side_step", "rig_leg", "ramp_cycles"})


class Knob(NamedTuple):
    """One searched value: its name, range [lo, hi] in the parameters' unit, and the
    parameters it sets."""

    name: str
    lo: float
    hi: float
    targets: tuple[str, ...]

    def values(self, x: float) -> dict[str, float]:
        return {t: x for t in self.targets}


def targets_of(name: str, where: str) -> tuple[str, ...]:
    if name in PAIRS:
        return PAIRS[name]
    canon = ALIASES.get(name, name)
    if canon not in SPECS:
        valid = ", ".join(sorted({*PAIRS, *(n for n in SPECS if n not in FIXED)}))
        raise ConfigError(f"{where}: unknown parameter {name!r}; valid: {valid}")
    if canon in FIXED:
        raise ConfigError(f"{where}: {canon} is not tuned (a command or a unit, not part "
                          "of the walk's quality); set it with --set")
    return (canon,)


def default_range(name: str, params: GaitParams, *, span: float = SPAN) -> tuple[float, float]:
    """The preset's value of ``name`` (a knob) x [1 - span, 1 + span], inside SPECS."""
    targets = targets_of(name, "--param")
    spec = SPECS[targets[0]]
    v = getattr(params, targets[0])
    if v == 0.0:
        half = span * (spec.hi - spec.lo) / 2
        lo, hi = -half, half
    else:
        lo, hi = sorted((v * (1 - span), v * (1 + span)))
    return max(lo, spec.lo), min(hi, spec.hi)


def parse_knob(text: str, params: GaitParams) -> Knob:
    """``NAME`` (default range) or ``NAME=LO:HI`` (checked against the documented range)."""
    where = f"--param {text}"
    name, sep, rng = text.partition("=")
    name = name.strip()
    targets = targets_of(name, where)
    if not sep:
        lo, hi = default_range(name, params)
        return Knob(name, lo, hi, targets)
    lo_text, colon, hi_text = rng.partition(":")
    try:
        lo, hi = float(lo_text), float(hi_text)
    except ValueError:
        lo = hi = float("nan")
    spec = SPECS[targets[0]]
    if not colon or not (spec.lo <= lo < hi <= spec.hi):
        raise ConfigError(f"{where}: expected {name}=LO:HI with {spec.lo:g} <= LO < HI <= "
                          f"{spec.hi:g} {spec.unit} (its documented range)")
    return Knob(name, lo, hi, targets)


def search_space(texts: Sequence[str], params: GaitParams, *, hip_yaw: bool = True,
                 robot_gait: Iterable[str] = ()) -> list[Knob]:
    """The knobs of ``--param`` items, or DEFAULT_KNOBS when none is given (and
    FIVE_DOF_KNOBS for legs without ``hip_yaw``); a parameter searched twice is an
    error. ``robot_gait``: the parameters the robot file's ``[gait]`` sets, which win over
    any preset (so a tuned preset could not change them): left out of the default search,
    and an error when ``--param`` names one."""
    fixed = set(robot_gait)
    default = DEFAULT_KNOBS if hip_yaw else DEFAULT_KNOBS + FIVE_DOF_KNOBS
    knobs = [parse_knob(t, params) for t in (texts or default)]
    for k in knobs:
        taken = fixed.intersection(k.targets)
        if taken and texts:
            raise ConfigError(f"--param {k.name}: {sorted(taken)[0]} is set by the robot "
                              "file's [gait], which wins over a preset: tune it on a copy of "
                              "the robot file without it, then put the result in [gait]")
    knobs = [k for k in knobs if not fixed.intersection(k.targets)]
    seen: set[str] = set()
    for k in knobs:
        clash = seen.intersection(k.targets)
        if clash:
            raise ConfigError(f"--param {k.name}: {sorted(clash)[0]} is searched twice")
        seen.update(k.targets)
    return knobs


def apply(params: GaitParams, knobs: Iterable[Knob], x: dict[str, float]) -> GaitParams:
    """``params`` with each knob at ``x[knob.name]`` (validated)."""
    changes: dict[str, float] = {}
    for k in knobs:
        changes.update(k.values(x[k.name]))
    return params.replace(changes, where="biped tune")
