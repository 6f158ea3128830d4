"""The paper's expressions (Bhatti et al., eq 1-20) on an integrated phase.

``T = t * fps`` is time in frames; eq 16 uses Maya's ``time`` in seconds. The printed
``sin(T * vM)`` jumps when vM changes live, so the phases are integrated
(``theta += vM * fps * dt``, one integrator per distinct frequency) and the printed
formulas are evaluated on the integrated phases. With constant parameters both agree.

The channels are written once against a tiny math namespace (``xp``) so the same code
serves one control tick on Python floats and a curve of a million frames on numpy arrays.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from robot.config.params import GaitParams
from robot.gait import xmath as xm
from robot.gait.xmath import Num

# The paper's constants (equations.md): J_error in eq 3, 6, 7; 20 and alpha 70 in eq 10.
J_ERROR_STY = 0.85
J_ERROR_CTY = 0.523
J_ERROR_STY_IK = 0.8
J_ERROR_STZ_IK = 0.02
FTAU_DIVISOR = 20.0
FTAU_ALPHA = 70.0

CHANNELS: tuple[str, ...] = (
    "f_pelvis", "f_spine", "ty", "tz", "StY", "StZ", "CtZ", "CtY", "StY_ik", "StZ_ik",
    "Ftau", "RightFoot_tY", "RightFoot_tZ", "LeftFoot_tY", "LeftFoot_tZ",
    "RightToe_tY", "LeftToe_tY", "RightUpLeg_tZ", "RightUpLeg_tY", "LeftUpLeg_tZ",
    "LeftUpLeg_tY", "Atau_R", "Atau_L", "RightArm_tY", "RightArm_tZ", "LeftArm_tY",
    "LeftArm_tZ", "RightShoulder_tY", "RightShoulder_tZ", "LeftShoulder_tY",
    "LeftShoulder_tZ",
)

class Phase(NamedTuple):
    """Integrated phase arguments of the paper's sines [rad].

    theta: T * vM (eq 8, 9, 10); pelvis: T * vM * phi (eq 1); spine: T * vM * k (eq 2);
    arm_R / arm_L: time * 2 * Abnc_R / Abnc_L (eq 16).
    """

    theta: Num
    pelvis: Num
    spine: Num
    arm_R: Num
    arm_L: Num


def phase_at(t: Num, p: GaitParams) -> Phase:
    """Phases at time(s) ``t`` [s] for constant parameters, grouped as printed. A phase
    equal to another by its parameters (k = 1, Abnc_L = Abnc_R) is that same object, so
    ``channels`` takes its sine once (x * 1.0 is x, bit for bit)."""
    T = t * p.fps
    theta = T * p.vM
    arm_R = t * 2 * p.Abnc_R
    return Phase(theta, theta * p.phi, theta if p.k == 1.0 else theta * p.k, arm_R,
                 arm_R if _same(p.Abnc_L, p.Abnc_R) else t * 2 * p.Abnc_L)


def _same(a: float, b: float) -> bool:
    """Equal, and zeros of the same sign."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


def advance(ph: Phase, p: GaitParams, dt: float) -> Phase:
    """Integrate the phases by ``dt`` [s] at the rates of the *current* parameters."""
    w = p.vM * p.fps * dt
    return Phase(ph.theta + w, ph.pelvis + w * p.phi, ph.spine + w * p.k,
                 ph.arm_R + 2 * p.Abnc_R * dt, ph.arm_L + 2 * p.Abnc_L * dt)


def channels(ph: Phase, p: GaitParams, *, amplitude: float = 1.0) -> dict[str, Num]:
    """Every channel of equations 1-20 at phase ``ph``.

    amplitude: start/stop envelope in [0, 1]; scales every sine/cosine and delta_f, so 1
    gives the printed formulas exactly and 0 the static posture the parameters describe.
    """
    a = amplitude
    s_theta = xm.sin(ph.theta)
    c_theta = xm.cos(ph.theta)
    s_pel = xm.sin(ph.pelvis)
    s_spi = s_theta if ph.spine is ph.theta else xm.sin(ph.spine)
    s_ftau = xm.sin(ph.theta - FTAU_ALPHA)
    s_ar = xm.sin(ph.arm_R)
    s_al = s_ar if ph.arm_L is ph.arm_R else xm.sin(ph.arm_L)
    delta_f = p.delta_f
    if a != 1.0:
        s_theta, c_theta, s_pel, s_spi = a * s_theta, a * c_theta, a * s_pel, a * s_spi
        s_ftau, s_ar, s_al, delta_f = a * s_ftau, a * s_ar, a * s_al, a * delta_f
    f_pelvis = s_pel * p.omegaB                                   # eq 1
    f_spine = s_spi * p.omegaC                                    # eq 2
    ty = s_theta + delta_f                                        # eq 8
    tz = c_theta                                                  # eq 9
    sty = p.Shgt + tz * p.omegaB - J_ERROR_STY                    # eq 3
    stz = tz * p.Sosc - p.Spos - f_spine - p.Hpos                 # eq 4
    ctz = tz * p.omegaB - p.Hpos                                  # eq 5
    cty = tz * p.Hosc / 4 + f_pelvis + p.Hhgt - J_ERROR_CTY       # eq 6
    ftau = s_ftau / FTAU_DIVISOR                                  # eq 10
    uplegy = p.Hhgt + f_pelvis - ty * p.Hosc                      # eq 14, 15
    atau_r = s_ar                                                 # eq 16
    atau_l = s_al
    return {
        "f_pelvis": f_pelvis,
        "f_spine": f_spine,
        "ty": ty,
        "tz": tz,
        "StY": sty,
        "StZ": stz,
        "CtZ": ctz,
        "CtY": cty,
        "StY_ik": sty + J_ERROR_STY_IK,                           # eq 7
        "StZ_ik": stz - J_ERROR_STZ_IK,
        "Ftau": ftau,
        "RightFoot_tY": ty * p.Fhgt_R,                            # eq 11
        "RightFoot_tZ": -tz * p.Slgt_R + p.Fpos_R,
        "LeftFoot_tY": -ty * p.Fhgt_L,                            # eq 12
        "LeftFoot_tZ": -tz * p.Slgt_L + p.Fpos_L,
        "RightToe_tY": ftau,                                      # eq 13
        "LeftToe_tY": -ftau,
        "RightUpLeg_tZ": tz * p.Hosc - p.Hpos,                    # eq 14
        "RightUpLeg_tY": uplegy,
        "LeftUpLeg_tZ": -tz * p.Hosc - p.Hpos,                    # eq 15
        "LeftUpLeg_tY": uplegy,
        "Atau_R": atau_r,                                         # eq 16
        "Atau_L": atau_l,
        "RightArm_tY": p.Ahgt_R - atau_r * p.Aosc_R,              # eq 17
        "RightArm_tZ": -tz * p.omega_ra + p.Apos_R,
        "LeftArm_tY": p.Ahgt_L - atau_l * p.Aosc_L,               # eq 18
        "LeftArm_tZ": tz * p.omega_la + p.Apos_L,
        "RightShoulder_tY": -ty * f_spine,                        # eq 19
        "RightShoulder_tZ": tz * f_spine,
        "LeftShoulder_tY": ty * f_spine,                          # eq 20
        "LeftShoulder_tZ": -tz * f_spine,
    }


def curves(times: npt.NDArray[np.float64], p: GaitParams) -> dict[str, npt.NDArray[np.float64]]:
    """All channels over an array of times [s] for constant parameters (vectorised)."""
    out = channels(phase_at(np.asarray(times, dtype=float), p), p)
    n = len(times)
    return {k: np.broadcast_to(np.asarray(v, dtype=float), (n,)) for k, v in out.items()}
