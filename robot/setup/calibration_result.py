"""What ``biped calibrate`` writes, joint by joint, and what it could not measure. Pure:
the measurements in, the file's new values and the summary's facts out.

A joint's limits are cut to what its servo reaches from the measured zero and sign
(``calibration.fit_limits``): a horn a spline tooth or two off centre narrows the range
instead of refusing the file. A rest angle (or an extra joint's ``fixed_rad``) outside the
new limits moves to the nearest limit. A joint whose servo reaches none of its limits keeps
its old values whole. Every joint whose sign or limits were asked for and not measured, and
every joint kept whole, makes the result incomplete (``biped calibrate`` exits 1), but the
measured joints are written all the same.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from robot.config.robot import JointConfig, RobotConfig
from robot.setup.calibration import fit_limits, hardware_range

Limits = tuple[float, float]


@dataclass(frozen=True)
class JointResult:
    """One joint after calibration.

    zero_ticks, sign, limits [rad]: what the file gets. sign_measured / limits_measured:
    None when the step did not ask (``--zero``; no ``--limits``). narrowed: the limits
    before they were cut to ``reach`` [rad] (what the servo reaches), else None. kept: the
    servo reaches none of the limits from the measured zero: the joint's old values are kept.
    """

    joint: JointConfig
    zero_ticks: int
    sign: int
    limits: Limits
    reach: Limits
    sign_measured: bool | None = None
    limits_measured: bool | None = None
    narrowed: Limits | None = None
    kept: bool = False

    @property
    def missing(self) -> list[str]:
        """What was asked for and not measured, in words (empty when complete)."""
        if self.kept:
            return ["zero, sign and limits (the servo reaches none of its limits)"]
        return [what for what, ok in (("sign", self.sign_measured),
                                      ("limits", self.limits_measured)) if ok is False]

    def fields(self) -> dict[str, int | float]:
        """The joint's values for the robot file."""
        if self.kept:
            return {}
        lo, hi = self.limits
        out: dict[str, int | float] = {"zero_ticks": self.zero_ticks, "sign": self.sign}
        if self.narrowed is not None or self.limits_measured:
            out.update(min_rad=lo, max_rad=hi)
        fixed = self.joint.fixed_rad
        if fixed is not None and not lo <= fixed <= hi:
            out["fixed_rad"] = min(max(fixed, lo), hi)
        return out


@dataclass(frozen=True)
class Calibration:
    """Every joint's result, the rest angles moved into the new limits and the name the
    written file gets."""

    joints: tuple[JointResult, ...]
    rest: Mapping[str, tuple[float, float]] = field(default_factory=dict)  # joint: (old, new)
    name: str | None = None

    @property
    def incomplete(self) -> dict[str, list[str]]:
        """``{joint: [what was not measured]}``; empty when the calibration is complete."""
        return {r.joint.name: r.missing for r in self.joints if r.missing}

    def changes(self) -> dict[str, dict[str, int | float]]:
        """``{joint: {field: value}}`` for ``toml_edit.write_validated``."""
        return {r.joint.name: r.fields() for r in self.joints if r.fields()}


def settle(robot: RobotConfig, zeros: Mapping[str, int], *,
           signs: Mapping[str, int] | None = None,
           limits: Mapping[str, Limits] | None = None,
           name: str | None = None) -> Calibration:
    """The calibration from the measurements: ``zeros`` [ticks] for every joint; ``signs``
    and ``limits`` [rad] for the joints measured (None: the step did not run). Limits are
    cut to the servo's whole tick range (its position-limit registers are configuration,
    not reach: measured limits are already inside them, ``limits_from_ends``)."""
    results = []
    for j in robot.joints:
        servo, zero = robot.servo(j), zeros[j.name]
        sign = signs.get(j.name, j.sign) if signs is not None else j.sign
        measured = limits.get(j.name) if limits is not None else None
        wanted = measured or (j.min_rad, j.max_rad)
        fitted = fit_limits(*wanted, zero=zero, sign=sign, resolution=servo.resolution,
                            ticks_per_rad=servo.ticks_per_rad)
        reach = hardware_range(zero, sign, servo.resolution, ticks_per_rad=servo.ticks_per_rad)
        results.append(JointResult(
            joint=j, zero_ticks=zero, sign=sign, limits=fitted or wanted,
            reach=reach, sign_measured=None if signs is None else j.name in signs,
            limits_measured=None if limits is None else measured is not None,
            narrowed=wanted if fitted is not None and fitted != wanted else None,
            kept=fitted is None))
    rest: dict[str, tuple[float, float]] = {}
    by_name = {r.joint.name: r for r in results}
    for jn, q in robot.rest.items():
        lo, hi = by_name[jn].limits if not by_name[jn].kept else (-float("inf"), float("inf"))
        if not lo <= q <= hi:
            rest[jn] = (q, min(max(q, lo), hi))
    return Calibration(tuple(results), rest, name)
