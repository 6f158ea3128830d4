"""One control tick on Python floats: the paper's channels → body targets → IK, fused.

``TickKernel.pose`` performs the operations of ``expressions.channels``,
``targets.body_targets``, ``ik_chain.chain_leg_ik`` / ``ik.arm_ik`` and ``engine.solve`` on floats, in
the same order, so it gives the same bits (tests/test_tick_kernel.py compares the two on
random inputs, bit for bit). It is the same arithmetic written as straight-line ``math``
code: no per-call type test, no intermediate dicts and tuples, helpers inlined, and what
does not change between ticks computed once: per robot in the constructor, per parameter
set when the parameters change (``GaitParams`` is frozen, so identity tells).

The legs' and arms' IK on floats are in robot.gait.tick_limbs (the box model's closed
form, ``simple`` legs) and robot.gait.tick_chain (robot.gait.ik_chain's, any other leg).
The general functions remain the definition (and serve the vectorised path); a change
there is made here too, and the test says whether the two still agree. Symbols follow
those modules; units: metres, radians, rig units where the paper's channels are.
"""

from __future__ import annotations

from math import cos, sin
from typing import NamedTuple

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.gait import xmath as xm
from robot.gait.expressions import FTAU_ALPHA, FTAU_DIVISOR, J_ERROR_STZ_IK, Phase
from robot.gait.rot_floats import apply_t as _apply_t
from robot.gait.rot_floats import per_foot as _per_foot
from robot.gait.rot_floats import rz_ry as _rz_ry
from robot.gait.rot_floats import t_matmul as _t_matmul
from robot.gait.targets import ARM_HANG, HAND_OUT, TURN_RANGE, BodyTrim, stride_shift
from robot.gait.tick_chain import leg_solver
from robot.gait.tick_limbs import Arm, arm_constants, arm_ik
from robot.gait.vectorised import spans


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
        r_chain, l_chain = robot.legs
        self._legs = (leg_solver(r_chain, r_leg), leg_solver(l_chain, l_leg))
        u, f = g.upper_arm, g.forearm
        self._hands: tuple[Arm, Arm] | None = (
            (arm_constants(u, f, -HAND_OUT, r_arm), arm_constants(u, f, HAND_OUT, l_arm))
            if r_arm is not None and l_arm is not None else None)
        self._hang = -ARM_HANG * (g.upper_arm + g.forearm)
        self._p: GaitParams | None = None
        self._derived: _Derived | None = None

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
        (r_ik, right), (l_ik, l_leg) = self._legs
        r_pel = _per_foot(pelvis, yaw, pitch, trim.roll, trim.r_roll, trim.r_pitch)
        l_pel = _per_foot(pelvis, yaw, pitch, trim.roll, trim.l_roll, trim.l_pitch)
        q, ok = r_ik(right, _apply_t(r_pel, rx_ - px + trim.r_dx, ry_ - py + trim.r_dy, rz_),
                     _t_matmul(r_pel, r_rot))
        q_l, ok_l = l_ik(l_leg, _apply_t(l_pel, lx_ - px + trim.l_dx, ly_ - py + trim.l_dy, lz_),
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
            q_a, ok_a = arm_ik(r_arm, sa * (-tz * p.omega_ra + p.Apos_R + tz * f_spine),
                               hang + sa * (p.Ahgt_R - s_ar * p.Aosc_R + -ty * f_spine))
            q += q_a
            ok = ok & ok_a
            q_a, ok_a = arm_ik(l_arm, sa * (tz * p.omega_la + p.Apos_L + -tz * f_spine),
                               hang + sa * (p.Ahgt_L - s_al * p.Aosc_L + ty * f_spine))
            q += q_a
            ok = ok & ok_a
        layout = self._layout
        if layout is not None:   # 5-DoF legs, extra joints held at fixed angles
            q = [q[i] if i >= 0 else fixed for i, fixed in layout]
        return q, lift_r, lift_l, ok
