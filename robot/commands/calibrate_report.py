"""What `biped calibrate` prints after writing the file: each joint whose limits were
narrowed (or that was kept whole), each rest angle moved, the table of old -> new values
with every value that was not measured flagged, the command that checks the file, and, when
something was not measured, one line on stderr and exit code 1."""

from __future__ import annotations

import sys
from pathlib import Path

from robot.config.robot import RobotConfig
from robot.setup.calibration_result import Calibration, JointResult


def _span(lo: float, hi: float) -> str:
    return f"[{lo:+.3f}, {hi:+.3f}]"


def _notes(r: JointResult) -> list[str]:
    j = r.joint
    reach = f"from zero_ticks {r.zero_ticks} its servo reaches {_span(*r.reach)} rad"
    if r.kept:
        return [f"{j.name}: {reach}, none of its limits {_span(j.min_rad, j.max_rad)}; the "
                "file keeps its old zero_ticks, sign and limits: re-mount the horn nearer "
                "the servo's centre and calibrate again"]
    notes = []
    if r.narrowed is not None:
        notes.append(f"{j.name}: limits {_span(*r.narrowed)} -> {_span(*r.limits)} rad: "
                     f"{reach} (a horn a spline tooth nearer its centre gets the range back)")
    fixed = r.fields().get("fixed_rad")
    if fixed is not None:
        notes.append(f"{j.name}: fixed_rad {j.fixed_rad:+.3f} -> {fixed:+.3f} rad (inside the "
                     "new limits)")
    return notes


def _row(r: JointResult) -> str:
    j = r.joint
    zero = r.zero_ticks if not r.kept else j.zero_ticks
    sign = f"{j.sign:+d} -> {r.sign if not r.kept else j.sign:+d}"
    sign += " (NOT measured)" if r.sign_measured is False or r.kept else ""
    if r.kept or r.limits_measured is False:
        lim = f"{_span(j.min_rad, j.max_rad)} (NOT measured)"
    elif r.narrowed is not None:
        lim = f"{_span(*r.limits)} (narrowed)"
    elif r.limits_measured:
        lim = _span(*r.limits)
    else:
        lim = f"{_span(*r.limits)} (kept)"
    return f"{j.name:<18} {j.zero_ticks:>6} -> {zero:<5} {sign:<22} {lim}"


def report(robot: RobotConfig, result: Calibration, out: Path, *, check: str) -> int:
    """Print the summary of ``result`` written to ``out``; ``check``: the command that checks
    the file. Returns the exit code: 0 complete, 1 when something was not measured."""
    notes = [n for r in result.joints for n in _notes(r)]
    notes += [f"rest.{jn}: {old:+.3f} -> {new:+.3f} rad (inside the new limits)"
              for jn, (old, new) in result.rest.items()]
    for note in notes:
        print(f"  {note}")
    print(f"{'joint':<18} {'zero_ticks':>15} {'sign':<22} limits [rad]")
    for r in result.joints:
        print(_row(r))
    named = f" (name {result.name!r}, from the file name)" if result.name else ""
    print(f"wrote {out}{named}; check it with `{check}` by moving joints by hand")
    missing = result.incomplete
    if not missing:
        return 0
    what = "; ".join(f"{jn} ({', '.join(m)})" for jn, m in missing.items())
    print(f"biped calibrate: incomplete: not measured: {what}; the file keeps their old "
          f"values and has every measured one; move those joints (a joint that never moves "
          f"may be a dead servo or cable) and run calibrate again on {out}", file=sys.stderr)
    return 1
