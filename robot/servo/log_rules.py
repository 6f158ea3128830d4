"""What a pendulum log (``robot.servo.pendulum_log``) must satisfy before it is replayed
or fitted: the rules, written once. The reader applies them to every log it reads
(``identify fit`` and ``check``), ``identify record`` to its arguments before a servo
moves and to every log before it is written. A broken rule is a ConfigError of one line,
``WHERE must be ... (got X)``, WHERE naming the file and the field (``LOG: mass``,
``LOG: entries[117].position``) or the option (``--mass``).

- Every number is finite (JSON as Python and JavaScript write it can say NaN, Infinity);
  goal and position within +-``MAX_ANGLE``, speed within +-``MAX_SPEED``.
- The rig (``robot.servo.bench_load.rig``, the rule ``identify record --mass / --length``
  and ``sim-gap`` / ``emulate --load`` share): ``mass`` and ``length`` > 0, within
  ``bench_load.MIN_MASS``..``MAX_MASS`` and ``MIN_LENGTH``..``MAX_LENGTH``;
  ``arm_mass`` >= 0.
- ``vin`` > 0 and at most ``MAX_VIN``.
- Time: each timestamp later than the one before; the duration from ``MIN_DURATION_S``
  to ``MAX_DURATION_S`` (see there why).
- ``kp``: an integer the P register the log names (``firmware.LOG_GAIN_REGISTERS``) can
  hold, its range from the manual as ``robot.servo.gains`` transcribes it; before the
  servo model is known, the widest such register (a servo model's own range once it is).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robot.errors import ConfigError
from robot.servo.bench_load import got, must, positive
from robot.servo.bench_load import rig as rig  # the rig's rule, shared with --load
from robot.servo.firmware import LOG_GAIN_REGISTERS
from robot.servo.gains import GAIN_SETS

Floats = npt.NDArray[np.float64]

#: [V]: the highest nominal supply of the servo models here is 24 V (XH430-V350); 30 V
#: leaves a charged pack's margin, and a typo of 240 is refused.
MAX_VIN = 30.0
#: [rad]: goal and position, from the arm hanging down: a position servo turns within one
#: turn, so two either way is room for any zero (the public recordings: within 1.8).
MAX_ANGLE = 2 * math.pi
#: [rad/s]: 2.5 times the fastest no-load speed of the servos here (XL330-M077, 40 rad/s);
#: an arm dropped with torque off swings far slower (0.1 m from level: 14 rad/s). Angles
#: or speeds past these put MuJoCo's replay out of range (it resets and the error means
#: nothing), so they are refused.
MAX_SPEED = 100.0
#: [s]: shorter than 20 samples at the replay's 5 ms carries no swing to check or fit
#: (the shortest run ``identify record`` makes is 1 s; the public recordings are 6 s).
MIN_DURATION_S = 0.1
#: [s]: five minutes, five times the longest run ``identify record`` makes (60 s) and
#: fifty times the public recordings. The replay holds every log of a set at 5 ms for
#: each candidate of a CMA-ES generation (10 copies): 300 s is 60,000 samples, about 5 MB
#: a log per copy over its four arrays; a stamp of 1e9 s would ask for terabytes. A servo
#: held against gravity that long overheats and the log stops being of one servo.
MAX_DURATION_S = 300.0


def supply(where: str, vin: float) -> None:
    """The supply during the run [V]."""
    positive(where, vin, least=0.0, most=MAX_VIN, unit="V")


def register_range(law: str | None) -> tuple[int, int, str]:
    """(lo, hi, what) of the P register a log's ``kp`` sets under ``law`` (None: the
    widest of all laws); ``what`` names it for messages."""
    names = [(s, r) for s, regs in LOG_GAIN_REGISTERS.items() if law in (None, s) for r in regs]
    if not names:   # a law without gain registers (LX): any register value
        names = [(s, r) for s, regs in LOG_GAIN_REGISTERS.items() for r in regs]
        law = None
    gains = [GAIN_SETS[s].gains[r] for s, r in names]
    lo, hi = min(g.lo for g in gains), max(g.hi for g in gains)
    what = (f"{law}'s {names[0][1]}" if law is not None
            else "a pendulum log's P gain register (any servo model)")
    return lo, hi, what


def register_value(where: str, value: float | int, *, law: str | None = None) -> int:
    """``value`` as the integer register value it must be (see ``register_range``)."""
    lo, hi, what = register_range(law)
    try:
        number = float(value)
    except OverflowError:           # a JSON integer of hundreds of digits
        number = math.inf
    if not (math.isfinite(number) and number.is_integer() and lo <= number <= hi):
        raise ConfigError(f"{where} must be an integer in {lo}..{hi}, {what} {got(number)}")
    return int(number)


def samples(where: str, name: str, values: Floats, *, most: float = math.inf,
            unit: str = "") -> None:
    """Every sample of series ``name`` finite, and within +-``most`` [unit]; ``where``:
    the log (the message names ``LOG: entries[i].name``)."""
    bad = np.flatnonzero(~np.isfinite(values))
    if len(bad):
        i = int(bad[0])
        raise must(f"{where}: entries[{i}].{name}", "a finite number", float(values[i]))
    far = np.flatnonzero(np.abs(values) > most)
    if len(far):
        i = int(far[0])
        raise must(f"{where}: entries[{i}].{name}", f"within +-{most:.3g} {unit}",
                    float(values[i]))


def times(where: str, t: Floats) -> None:
    """The timestamps [s]: finite, each later than the one before, a plausible span."""
    if len(t) < 2:
        raise ConfigError(f"{where}: entries must be at least 2 samples (got {len(t)})")
    samples(where, "timestamp", t)
    back = np.flatnonzero(np.diff(t) <= 0)
    if len(back):
        i = int(back[0]) + 1
        raise ConfigError(f"{where}: entries[{i}].timestamp must be later than "
                          f"entries[{i - 1}]'s ({t[i - 1]:g} s) {got(float(t[i]))}")
    span = float(t[-1] - t[0])
    if span < MIN_DURATION_S:
        raise ConfigError(f"{where}: duration must be at least {MIN_DURATION_S:g} s "
                          f"(got {span:g} s)")
    if span > MAX_DURATION_S:
        raise ConfigError(f"{where}: duration must be at most {MAX_DURATION_S:g} s "
                          f"(a pendulum run; first to last timestamp) (got {span:g} s)")


def flag(where: str, value: object) -> bool:
    """A JSON boolean (or 0 / 1, as some recorders write it)."""
    if isinstance(value, bool) or (isinstance(value, int) and value in (0, 1)):
        return bool(value)
    raise ConfigError(f"{where} must be true or false (got {value!r:.40})")
