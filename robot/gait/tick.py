"""One control tick on Python floats: the paper's channels → body targets → IK, fused.

``TickKernel.pose`` performs the operations of ``expressions.channels``,
``targets.body_targets``, ``ik.leg_ik`` / ``ik.arm_ik`` and ``engine.solve`` on floats, in
the same order, so it gives the same bits (tests/test_tick_kernel.py compares the two on
random inputs, bit for bit). It is the same arithmetic written as straight-line ``math``
code: no per-call type test, no intermediate dicts and tuples, helpers inlined, and what
does not change between ticks computed once: per robot in the constructor, per parameter
set when the parameters change (``GaitParams`` is frozen, so identity tells).

The general functions remain the definition (and serve the vectorised path); a change
there is made here too, and the test says whether the two still agree. Symbols follow
those modules; units: metres, radians, rig units where the paper's channels are.
"""

from __future__ import annotations

from math import atan2, cos, sin, sqrt
from typing import NamedTuple

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.gait import xmath as xm
from robot.gait.expressions import FTAU_ALPHA, FTAU_DIVISOR, J_ERROR_STZ_IK, Phase
from robot.gait.ik import REACH_TOL, SIDE_SIGN, Reach
from robot.gait.rot_floats import apply_t as _apply_t
from robot.gait.rot_floats import per_foot as _per_foot
from robot.gait.rot_floats import rz_ry as _rz_ry
from robot.gait.rot_floats import t_matmul as _t_matmul
from robot.gait.targets import ARM_HANG, HAND_OUT, TURN_RANGE, BodyTrim, stride_shift
from robot.gait.vectorised import spans
from robot.gait.xmath import Rot


class _Leg(NamedTuple):
    """Per-leg constants of ``ik.leg_ik`` [m, m^2]."""

    hx: float
    hy: float
    hz: float
    a: float       # thigh
    b: float       # shin
    ah: float      # ankle height
    far: float     # a + b
    near: float    # |a - b|
    span: float    # 4 a b
    lo: float      # c_lo - REACH_TOL
    hi: float      # c_hi + REACH_TOL
    c_lo: float    # the hip to ankle distances the knee limits allow (ik.leg_reach)
    c_hi: float


class _Arm(NamedTuple):
    """Per-arm constants of ``ik.arm_ik`` for the fixed lateral hand offset ``py`` [m]."""

    py: float
    py2: float     # py * py
    lo: float      # the distances the elbow limits allow (ik.arm_reach)
    hi: float
    far: float     # u + f
    near: float    # |u - f|
    far_s: float   # (far - |py|) (far + |py|) of ik.spans
    s_near: float  # (|py| - near) (|py| + near) of ik.spans
    span: float    # 4 u f
    two_u: float   # 2 u
    f_u: float     # f - u
    lo_tol: float  # lo - REACH_TOL
    hi_tol: float  # hi + REACH_TOL


class _Derived(NamedTuple):
    """What ``body_targets`` derives from the parameters alone."""

    s: float         # metres per rig unit
    s_half: float    # s * 0.5
    hip_h0: float    # stance * leg length + ankle height [m]
    c_sway: float    # cos(sway_phase)
    s_sway: float    # sin(sway_phase)
    half_w: float    # hip_width / 2 + foot_spread [m]
    side: float      # 0.5 * side_step [m]
    s_fhgt_l: float  # s * Fhgt_L [m/rig]
    neg_toe: float   # -toe_gain [rad/rig]
    sa: float        # s * arm_scale


class TickKernel:
    """``pose`` for one robot on Python floats (see the module docstring)."""

    def __init__(self, robot: RobotConfig) -> None:
        g = robot.geometry
        self._g = g
        self._leg_yaw = robot.has_hip_yaw
        self._layout = robot.layout
        r_leg, l_leg, r_arm, l_arm = spans(robot)
        self._legs = (self._leg("r", r_leg), self._leg("l", l_leg))
        self._hands: tuple[_Arm, _Arm] | None = (
            (self._arm(-HAND_OUT, r_arm), self._arm(HAND_OUT, l_arm))
            if r_arm is not None and l_arm is not None else None)
        self._hang = -ARM_HANG * (g.upper_arm + g.forearm)
        self._p: GaitParams | None = None
        self._derived: _Derived | None = None

    def _leg(self, side: str, span: Reach) -> _Leg:
        g = self._g
        a, b = g.thigh, g.shin
        return _Leg(0.0, SIDE_SIGN[side] * g.hip_width / 2, 0.0, a, b, g.ankle_height, a + b,
                    abs(a - b), 4.0 * a * b, span.lo - REACH_TOL, span.hi + REACH_TOL,
                    span.lo, span.hi)

    def _arm(self, py: float, span: Reach) -> _Arm:
        u, f = self._g.upper_arm, self._g.forearm
        far, near, s = u + f, abs(u - f), abs(py)
        return _Arm(py, py * py, span.lo, span.hi, far, near, (far - s) * (far + s),
                    (s - near) * (s + near), 4.0 * u * f, 2.0 * u, f - u,
                    span.lo - REACH_TOL, span.hi + REACH_TOL)

    def _derive(self, p: GaitParams) -> _Derived:
        g = self._g
        s = g.leg_length / p.rig_leg
        d = _Derived(s, s * 0.5, p.stance * g.leg_length + g.ankle_height, cos(p.sway_phase),
                     sin(p.sway_phase), g.hip_width / 2 + p.foot_spread, 0.5 * p.side_step,
                     s * p.Fhgt_L, -p.toe_gain, s * p.arm_scale)
        self._p, self._derived = p, d
        return d

    def pose(self, ph: Phase, p: GaitParams, amplitude: float, trim: BodyTrim
             ) -> tuple[list[float], float, float, bool]:
        """Joint angles [rad] in the robot's joint order (as ``engine.solve``: not yet
        clamped to the joint limits), the right and left foot lift [m] (``BodyTargets``)
        and whether every target was reachable."""
        d = self._derived if p is self._p and self._derived is not None else self._derive(p)
        # -- expressions.channels (only the channels body_targets reads) ------------------
        a = amplitude
        s_theta, c_theta = sin(ph.theta), cos(ph.theta)
        s_pel, s_spi = sin(ph.pelvis), sin(ph.spine)
        s_ftau = sin(ph.theta - FTAU_ALPHA)
        delta_f = p.delta_f
        if a != 1.0:
            s_theta, c_theta, s_pel, s_spi = a * s_theta, a * c_theta, a * s_pel, a * s_spi
            s_ftau, delta_f = a * s_ftau, a * delta_f
        f_pelvis = s_pel * p.omegaB
        f_spine = s_spi * p.omegaC
        ty = s_theta + delta_f
        tz = c_theta
        stz_ik = tz * p.Sosc - p.Spos - f_spine - p.Hpos - J_ERROR_STZ_IK
        ctz = tz * p.omegaB - p.Hpos
        ftau = s_ftau / FTAU_DIVISOR
        upleg_ty = p.Hhgt + f_pelvis - ty * p.Hosc
        r_upleg_tz = tz * p.Hosc - p.Hpos
        l_upleg_tz = -tz * p.Hosc - p.Hpos

        # -- targets.body_targets: pelvis ----------------------------------------------------
        s = d.s
        a_delta = amplitude * p.delta_f
        sin_t = ty - a_delta
        hip_h = d.hip_h0 + s * upleg_ty
        px = d.s_half * (r_upleg_tz + l_upleg_tz)
        yaw = s * (r_upleg_tz - l_upleg_tz) / self._g.hip_width if self._leg_yaw else 0.0
        py = p.sway * (sin_t * d.c_sway - tz * d.s_sway)
        pitch = p.torso_lean + trim.pitch + p.spine_gain * (stz_ik - ctz)
        pelvis = _rz_ry(yaw, pitch)
        if trim.roll != 0.0:
            pelvis = xm.post_rx(pelvis, trim.roll)

        # -- feet --------------------------------------------------------------------------
        ty_l = 2.0 * a_delta - ty
        lift_r = s * (ty * p.Fhgt_R)
        lift_r = lift_r if lift_r > 0.0 else 0.0
        lift_l = d.s_fhgt_l * ty_l
        lift_l = lift_l if lift_l > 0.0 else 0.0
        down = 1.0 - trim.land
        stride_r = -tz * p.Slgt_R + p.Fpos_R - p.Fpos_R
        stride_l = -(-tz * p.Slgt_L + p.Fpos_L - p.Fpos_L)
        half_w = d.half_w
        rx_, ry_, rz_ = (s * (p.speed * stride_r + p.Fpos_R), -half_w - d.side * tz,
                         -hip_h + lift_r * down)
        lx_, ly_, lz_ = (s * (p.speed * stride_l + p.Fpos_L), half_w + d.side * tz,
                         -hip_h + lift_l * down)
        w_r = (0.0 if ty < 0.0 else 1.0 if ty > 1.0 else ty) * down
        w_l = (0.0 if ty_l < 0.0 else 1.0 if ty_l > 1.0 else ty_l) * down
        turn = (p.turn if trim.turn == 0.0
                else min(max(p.turn + trim.turn, TURN_RANGE[0]), TURN_RANGE[1]))
        yaw_turn = turn if self._leg_yaw else 0.0
        yaw_r = -0.5 * yaw_turn * tz
        yaw_l = 0.5 * yaw_turn * tz
        r_rot = _rz_ry(yaw_r, d.neg_toe * ftau * w_r)
        l_rot = _rz_ry(yaw_l, d.neg_toe * -ftau * w_l)
        shift = 0.0 if self._leg_yaw else stride_shift(p, trim.turn, half_w, s)
        if shift != 0.0:                         # 5-DoF: by step length
            rx_, lx_ = rx_ - shift * tz, lx_ - shift * tz
        if yaw_turn != 0.0:  # targets._yawed, with cos and sin of the yaw from the rotations
            c, sn = r_rot[4], -r_rot[1]
            rx_, ry_ = c * rx_ - sn * ry_, sn * rx_ + c * ry_
            c, sn = l_rot[4], -l_rot[1]
            lx_, ly_ = c * lx_ - sn * ly_, sn * lx_ + c * ly_
        right, l_leg = self._legs
        r_pel = _per_foot(pelvis, yaw, pitch, trim.roll, trim.r_roll, trim.r_pitch)
        l_pel = _per_foot(pelvis, yaw, pitch, trim.roll, trim.l_roll, trim.l_pitch)
        q, ok = _leg_ik(right, _apply_t(r_pel, rx_ - px + trim.r_dx, ry_ - py + trim.r_dy, rz_),
                        _t_matmul(r_pel, r_rot))
        q_l, ok_l = _leg_ik(l_leg, _apply_t(l_pel, lx_ - px + trim.l_dx,
                                             ly_ - py + trim.l_dy, lz_),
                            _t_matmul(l_pel, l_rot))
        q += q_l
        ok = ok & ok_l
        if self._hands is not None:
            # -- hands relative to the shoulders, then the arms' IK ------------------------
            s_ar, s_al = sin(ph.arm_R), sin(ph.arm_L)
            if a != 1.0:
                s_ar, s_al = a * s_ar, a * s_al
            sa, hang = d.sa, self._hang
            r_arm, l_arm = self._hands
            # RightArm_tZ + RightShoulder_tZ forward, RightArm_tY + RightShoulder_tY up
            q_a, ok_a = _arm_ik(r_arm, sa * (-tz * p.omega_ra + p.Apos_R + tz * f_spine),
                                hang + sa * (p.Ahgt_R - s_ar * p.Aosc_R + -ty * f_spine))
            q += q_a
            ok = ok & ok_a
            q_a, ok_a = _arm_ik(l_arm, sa * (tz * p.omega_la + p.Apos_L + -tz * f_spine),
                                hang + sa * (p.Ahgt_L - s_al * p.Aosc_L + ty * f_spine))
            q += q_a
            ok = ok & ok_a
        layout = self._layout
        if layout is not None:   # 5-DoF legs, extra joints held at fixed angles
            q = [q[i] if i >= 0 else fixed for i, fixed in layout]
        return q, lift_r, lift_l, ok


def _leg_ik(k: _Leg, sole: tuple[float, float, float], f: Rot) -> tuple[list[float], bool]:
    """ik.leg_ik on floats: the six leg angles [rad] and the reachable flag."""
    hx, hy, hz, a, b, ah, far, near, span, lo, hi, c_lo, c_hi = k
    f0, f1, f2, f3, f4, f5, f6, f7, f8 = f
    x = hx - (sole[0] + f2 * ah)   # ankle → hip
    y = hy - (sole[1] + f5 * ah)
    z = hz - (sole[2] + f8 * ah)
    rx = f0 * x + f3 * y + f6 * z    # in the foot frame
    ry = f1 * x + f4 * y + f7 * z
    rz = f2 * x + f5 * y + f8 * z
    c = sqrt(rx * rx + ry * ry + rz * rz)
    reachable = (c >= lo) & (c <= hi)
    c = c_lo if c < c_lo else c_hi if c > c_hi else c
    s = abs(c)                       # ik.spans and ik.bend with t = 0
    out = (far - s) * (far + s) - 0.0
    out = 0.0 if out < 0.0 else span if out > span else out
    inn = (s - near) * (s + near) + 0.0
    inn = 0.0 if inn < 0.0 else span if inn > span else inn
    knee = 2.0 * atan2(sqrt(out), sqrt(inn))
    ankle_a = atan2(a * sin(knee), b + a * cos(knee))
    sz_ = 1.0 if rz >= 0 else -1.0
    ankle_roll = atan2(ry * sz_, rz * sz_)
    ankle_pitch = -atan2(rx, sz_ * sqrt(ry * ry + rz * rz)) - ankle_a
    ankle_pitch = atan2(sin(ankle_pitch), cos(ankle_pitch))
    # r = post_ry(post_rx(f, -ankle_roll), -(ankle_pitch + knee)): the entries the hip needs
    cr, sr = cos(-ankle_roll), sin(-ankle_roll)
    r1, r4, r7 = cr * f1 + sr * f2, cr * f4 + sr * f5, cr * f7 + sr * f8
    r8 = cr * f8 - sr * f7
    t = -(ankle_pitch + knee)
    cp, sp = cos(t), sin(t)
    r6, r8 = cp * f6 - sp * r8, sp * f6 + cp * r8
    hip_yaw = atan2(-r1, r4)
    cz, sz = cos(hip_yaw), sin(hip_yaw)
    hip_roll = atan2(r7, -r1 * sz + r4 * cz)
    hip_pitch = atan2(-r6, r8)
    return [hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll], reachable


def _arm_ik(k: _Arm, px: float, pz: float) -> tuple[list[float], bool]:
    """ik.arm_ik on floats for the hand at (px, k.py, pz) [m]: three arm angles [rad] and
    the reachable flag."""
    py, py2, lo, hi, far, near, far_s, s_near, span, two_u, f_u, lo_tol, hi_tol = k
    rho2 = px * px + pz * pz
    d = sqrt(rho2 + py2)
    dc = lo if d < lo else hi if d > hi else d
    kk = dc / (d if d > 1e-300 else 1e-300)
    y = py * kk
    y = -dc if y < -dc else dc if y > dc else y
    t = sqrt(rho2)                   # ik.spans(u, f, py * kk, t * kk)
    if kk == 1.0:                    # inside the reach: py's terms precomputed
        t2 = t * t
        out = far_s - t2
        inn = s_near + t2
    else:
        sk, tk = abs(py * kk), t * kk
        t2 = tk * tk
        out = (far - sk) * (far + sk) - t2
        inn = (sk - near) * (sk + near) + t2
    out = 0.0 if out < 0.0 else span if out > span else out
    inn = 0.0 if inn < 0.0 else span if inn > span else inn
    elbow = -2.0 * atan2(sqrt(out), sqrt(inn))
    vx = sqrt(out * inn) / two_u
    vz = f_u - inn / two_u
    ay, az, rr, zz = abs(y), abs(vz), rho2 * kk * kk, vz * vz
    m = rr + zz
    lat2 = (zz * (rr - vx * vx) + rr * (az - ay) * (az + ay)) / (m if m > 1e-300 else 1e-300)
    sign_y = 1.0 if y >= 0 else -1.0
    sign_vz = 1.0 if vz >= 0 else -1.0
    roll = atan2(-sign_y * sign_vz * 0.5 * (ay + az - abs(ay - az)), sqrt(abs(lat2)))
    w = cos(roll) * vz
    pitch = atan2(px * w - pz * vx, pz * w + px * vx + 0.0)
    reachable = (d >= lo_tol) & (d <= hi_tol) & (ay <= az + REACH_TOL)
    return [pitch, roll, elbow], reachable
