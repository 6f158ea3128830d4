"""Gait parameters: the paper's symbols plus the robot mapping's, with documented ranges.

``SPECS`` is the single source of truth for every parameter: default, range, unit, group
(as the paper groups its sliders) and meaning. Config loading, live updates, docs and the
panel all read it.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from robot.config.balance_params import BALANCE_GAINS
from robot.config.stairs_params import STAIRS
from robot.config.toml_io import show
from robot.errors import ConfigError


class ParamSpec(NamedTuple):
    """Metadata of one gait parameter.

    default: value when a gait file omits it
    lo, hi: inclusive valid range
    unit: unit string ("rad/frame", "rig", "m", ...)
    group: panel / docs group
    doc: one-line meaning
    paper: True for the paper's own symbols, False for the robot mapping's
    """

    default: float
    lo: float
    hi: float
    unit: str
    group: str
    doc: str
    paper: bool = True


PELVIS = "pelvis and spine"
LEGS = "legs and feet"
ARMS = "shoulders and arms"
STEER = "steering"
ROBOT = "robot mapping"
BALANCE = "balance feedback"

SPECS: dict[str, ParamSpec] = {
    # --- timing ---------------------------------------------------------------------
    "fps": ParamSpec(24.0, 1.0, 240.0, "frame/s", PELVIS, "frames per second: T = t * fps"),
    "vM": ParamSpec(0.25, 0.0, 2.0, "rad/frame", PELVIS, "velocity of the forward motion"),
    "phi": ParamSpec(2.0, 0.0, 10.0, "-", PELVIS, "phase multiplier of the pelvis bob (eq 1)"),
    "omegaB": ParamSpec(0.1, 0.0, 2.0, "rig", PELVIS, "body (pelvis) oscillation amplitude"),
    "omegaC": ParamSpec(0.1, 0.0, 2.0, "rig", PELVIS, "chest oscillation amplitude (eq 2)"),
    "k": ParamSpec(1.0, 0.0, 5.0, "-", PELVIS, "spine frequency constant (eq 2)"),
    "Hosc": ParamSpec(0.1, 0.0, 2.0, "rig", PELVIS, "hip oscillation"),
    "Hhgt": ParamSpec(0.0, -2.0, 2.0, "rig", PELVIS, "hip height"),
    "Hpos": ParamSpec(0.0, -2.0, 2.0, "rig", PELVIS, "hip position (forward)"),
    "Sosc": ParamSpec(0.1, 0.0, 2.0, "rig", PELVIS, "spine / shoulder oscillation"),
    "Shgt": ParamSpec(0.85, 0.0, 2.0, "rig", PELVIS, "spine / shoulder height"),
    "Spos": ParamSpec(0.0, -2.0, 2.0, "rig", PELVIS, "spine / shoulder position (forward)"),
    # --- legs and feet ------------------------------------------------------------------
    "delta_f": ParamSpec(0.0, -1.0, 1.0, "-", LEGS, "foot distance from ground (eq 8 offset)"),
    "Fhgt_R": ParamSpec(0.5, 0.0, 3.0, "rig", LEGS, "right foot height during motion"),
    "Fhgt_L": ParamSpec(0.5, 0.0, 3.0, "rig", LEGS, "left foot height during motion"),
    "Fpos_R": ParamSpec(0.0, -2.0, 2.0, "rig", LEGS, "right foot position w.r.t. the body"),
    "Fpos_L": ParamSpec(0.0, -2.0, 2.0, "rig", LEGS, "left foot position w.r.t. the body"),
    "Slgt_R": ParamSpec(0.5, 0.0, 3.0, "rig", LEGS, "right stride length"),
    "Slgt_L": ParamSpec(0.5, 0.0, 3.0, "rig", LEGS, "left stride length"),
    # --- shoulders and arms ---------------------------------------------------------------
    "Abnc_R": ParamSpec(1.0, 0.0, 20.0, "rad/s", ARMS, "bounciness of the right arm (eq 16)"),
    "Abnc_L": ParamSpec(1.0, 0.0, 20.0, "rad/s", ARMS, "bounciness of the left arm (eq 16)"),
    "omega_ra": ParamSpec(0.5, -3.0, 3.0, "rig", ARMS, "right arm swing amplitude"),
    "omega_la": ParamSpec(0.5, -3.0, 3.0, "rig", ARMS, "left arm swing amplitude"),
    "Apos_R": ParamSpec(0.0, -3.0, 3.0, "rig", ARMS, "right wrist position (forward), alias Wpos_R"),
    "Apos_L": ParamSpec(0.0, -3.0, 3.0, "rig", ARMS, "left wrist position (forward), alias Wpos_L"),
    "Ahgt_R": ParamSpec(0.0, -3.0, 6.0, "rig", ARMS, "right wrist height, alias Whgt_R"),
    "Ahgt_L": ParamSpec(0.0, -3.0, 6.0, "rig", ARMS, "left wrist height, alias Whgt_L"),
    "Aosc_R": ParamSpec(0.1, 0.0, 2.0, "rig", ARMS, "right wrist oscillation, alias Wosc_R"),
    "Aosc_L": ParamSpec(0.1, 0.0, 2.0, "rig", ARMS, "left wrist oscillation, alias Wosc_L"),
    # --- steering (robot mapping) -----------------------------------------------------------
    "speed": ParamSpec(1.0, -1.0, 1.5, "-", STEER, "stride multiplier; negative walks backward", False),
    "turn": ParamSpec(0.0, -0.5, 0.5, "rad/step", STEER, "turn per step, + = left (hip yaw)", False),
    "side_step": ParamSpec(0.0, -0.025, 0.025, "m/step", STEER, "side step per step, + = left "
                           "(walks over the whole range with balance on)", False),
    # --- robot mapping ------------------------------------------------------------------------
    "rig_leg": ParamSpec(4.0, 1.0, 20.0, "rig", ROBOT, "leg length of the paper's rig in rig units; "
                         "metres = rig * robot_leg / rig_leg", False),
    "stance": ParamSpec(0.88, 0.6, 0.99, "-", ROBOT, "standing hip height / straight-leg length", False),
    "sway": ParamSpec(0.0, 0.0, 0.06, "m", ROBOT, "lateral weight shift amplitude", False),
    "sway_phase": ParamSpec(0.0, -math.pi, math.pi, "rad", ROBOT, "sway lag behind the stride", False),
    "foot_spread": ParamSpec(0.0, -0.02, 0.05, "m", ROBOT, "extra lateral distance of each foot", False),
    "torso_lean": ParamSpec(0.0, -0.4, 0.4, "rad", ROBOT, "static forward lean of the torso", False),
    "spine_gain": ParamSpec(0.0, -2.0, 2.0, "rad/rig", ROBOT, "torso pitch per rig unit of "
                            "StZ_ik - CtZ (eq 4-7; no spine joint)", False),
    "toe_gain": ParamSpec(1.0, 0.0, 10.0, "rad/rig", ROBOT, "foot pitch per unit of Ftau "
                          "(eq 10, 13) while the foot is lifted", False),
    "arm_scale": ParamSpec(1.0, 0.0, 3.0, "-", ROBOT, "scale of arm channels to the arm length", False),
    "ramp_cycles": ParamSpec(1.0, 0.1, 10.0, "cycle", ROBOT, "gait cycles to ramp amplitudes "
                             "in and out", False),
    # --- a staircase the user describes (robot/config/stairs_params.py) -----------------------
    **{n: ParamSpec(d, lo, hi, u, ROBOT, doc, False) for n, (d, lo, hi, u, doc) in STAIRS.items()},
    # --- balance feedback (robot/config/balance_params.py) ----------------------------------
    **{n: ParamSpec(d, lo, hi, u, BALANCE, doc, False)
       for n, (d, lo, hi, u, doc) in BALANCE_GAINS.items()},
}

ALIASES: dict[str, str] = {
    "Wpos_R": "Apos_R",
    "Wpos_L": "Apos_L",
    "Whgt_R": "Ahgt_R",
    "Whgt_L": "Ahgt_L",
    "Wosc_R": "Aosc_R",
    "Wosc_L": "Aosc_L",
}

GROUPS: tuple[str, ...] = (PELVIS, LEGS, ARMS, STEER, ROBOT, BALANCE)


@dataclass(frozen=True)
class GaitParams:
    """Every gait parameter (see ``SPECS`` for units and ranges)."""

    fps: float = SPECS["fps"].default
    vM: float = SPECS["vM"].default
    phi: float = SPECS["phi"].default
    omegaB: float = SPECS["omegaB"].default
    omegaC: float = SPECS["omegaC"].default
    k: float = SPECS["k"].default
    Hosc: float = SPECS["Hosc"].default
    Hhgt: float = SPECS["Hhgt"].default
    Hpos: float = SPECS["Hpos"].default
    Sosc: float = SPECS["Sosc"].default
    Shgt: float = SPECS["Shgt"].default
    Spos: float = SPECS["Spos"].default
    delta_f: float = SPECS["delta_f"].default
    Fhgt_R: float = SPECS["Fhgt_R"].default
    Fhgt_L: float = SPECS["Fhgt_L"].default
    Fpos_R: float = SPECS["Fpos_R"].default
    Fpos_L: float = SPECS["Fpos_L"].default
    Slgt_R: float = SPECS["Slgt_R"].default
    Slgt_L: float = SPECS["Slgt_L"].default
    Abnc_R: float = SPECS["Abnc_R"].default
    Abnc_L: float = SPECS["Abnc_L"].default
    omega_ra: float = SPECS["omega_ra"].default
    omega_la: float = SPECS["omega_la"].default
    Apos_R: float = SPECS["Apos_R"].default
    Apos_L: float = SPECS["Apos_L"].default
    Ahgt_R: float = SPECS["Ahgt_R"].default
    Ahgt_L: float = SPECS["Ahgt_L"].default
    Aosc_R: float = SPECS["Aosc_R"].default
    Aosc_L: float = SPECS["Aosc_L"].default
    speed: float = SPECS["speed"].default
    turn: float = SPECS["turn"].default
    side_step: float = SPECS["side_step"].default
    rig_leg: float = SPECS["rig_leg"].default
    stance: float = SPECS["stance"].default
    sway: float = SPECS["sway"].default
    sway_phase: float = SPECS["sway_phase"].default
    foot_spread: float = SPECS["foot_spread"].default
    torso_lean: float = SPECS["torso_lean"].default
    spine_gain: float = SPECS["spine_gain"].default
    toe_gain: float = SPECS["toe_gain"].default
    arm_scale: float = SPECS["arm_scale"].default
    ramp_cycles: float = SPECS["ramp_cycles"].default
    stairs_rise: float = SPECS["stairs_rise"].default
    stairs_count: float = SPECS["stairs_count"].default
    stairs_tread: float = SPECS["stairs_tread"].default
    stairs_x0: float = SPECS["stairs_x0"].default
    stairs_landing: float = SPECS["stairs_landing"].default
    stairs_margin: float = SPECS["stairs_margin"].default
    stairs_margin_back: float = SPECS["stairs_margin_back"].default
    stairs_odometry: float = SPECS["stairs_odometry"].default
    stairs_learn: float = SPECS["stairs_learn"].default
    stairs_slow: float = SPECS["stairs_slow"].default
    stairs_close: float = SPECS["stairs_close"].default
    stairs_reach: float = SPECS["stairs_reach"].default
    bal_ankle_pd: float = SPECS["bal_ankle_pd"].default
    bal_hip_pd: float = SPECS["bal_hip_pd"].default
    bal_ankle_pp: float = SPECS["bal_ankle_pp"].default
    bal_lean_i: float = SPECS["bal_lean_i"].default
    bal_lean_max: float = SPECS["bal_lean_max"].default
    bal_step_gain: float = SPECS["bal_step_gain"].default
    bal_step_max: float = SPECS["bal_step_max"].default
    bal_step_dead: float = SPECS["bal_step_dead"].default
    bal_brace_xi: float = SPECS["bal_brace_xi"].default
    bal_brace_s: float = SPECS["bal_brace_s"].default
    bal_brace_max_s: float = SPECS["bal_brace_max_s"].default
    bal_hold_xi: float = SPECS["bal_hold_xi"].default
    bal_tempo_max: float = SPECS["bal_tempo_max"].default
    bal_swing_level: float = SPECS["bal_swing_level"].default
    bal_kin_xi: float = SPECS["bal_kin_xi"].default
    bal_learn_cycles: float = SPECS["bal_learn_cycles"].default
    bal_heading_p: float = SPECS["bal_heading_p"].default
    bal_heading_i: float = SPECS["bal_heading_i"].default
    bal_turn_max: float = SPECS["bal_turn_max"].default
    bal_stop_close: float = SPECS["bal_stop_close"].default
    bal_stride_turn: float = SPECS["bal_stride_turn"].default

    def replace(self, changes: Mapping[str, Any], *, where: str = "parameter") -> GaitParams:
        """A copy with ``changes`` applied after validating every one of them.

        Raises ConfigError (naming ``where`` and the parameter) and changes nothing if any
        value is unknown, not a finite number or outside its range.
        """
        clean = {canonical_name(n, where=where): check_value(n, v, where=where)
                 for n, v in changes.items()}
        return dataclasses.replace(self, **clean)

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)

    # Derived values are cached on the (frozen) instance: the control loop reads them
    # every tick. They are not fields (replace, as_dict and equality ignore them).
    @functools.cached_property
    def omega(self) -> float:
        """Main phase rate d(theta)/dt [rad/s]."""
        return self.vM * self.fps

    @functools.cached_property
    def cycle_s(self) -> float:
        """Duration of one gait cycle [s] (inf when vM is 0)."""
        return math.inf if self.omega == 0 else 2 * math.pi / self.omega


def canonical_name(name: str, *, where: str = "parameter") -> str:
    """Resolve aliases; raise ConfigError listing the valid names for an unknown one."""
    name = ALIASES.get(name, name)
    if name not in SPECS:
        valid = ", ".join(SPECS)
        raise ConfigError(f"{where}: unknown gait parameter {name!r}; valid: {valid}")
    return name


def check_value(name: str, value: Any, *, where: str = "parameter") -> float:
    """Validate one parameter value and return it as float."""
    name = canonical_name(name, where=where)
    spec = SPECS[name]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{where}: {name} must be a number in [{spec.lo:g}, {spec.hi:g}] "
                          f"{spec.unit}, got {show(value)}")
    # Range first: float() of a 400-digit integer raises OverflowError.
    if not (spec.lo <= value <= spec.hi):  # also false for nan
        raise ConfigError(f"{where}: {name} = {show(value)} is outside [{spec.lo:g}, "
                          f"{spec.hi:g}] {spec.unit} ({spec.doc})")
    return float(value)


# Sanity: SPECS and GaitParams must name the same parameters in the same order.
assert tuple(SPECS) == tuple(f.name for f in dataclasses.fields(GaitParams))
