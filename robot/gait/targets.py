"""Paper channels → metric body targets for a physical biped (the documented corrections).

The paper animates a Maya rig (Y up, Z forward, rig units). Here, once:
- axes: rig Z (forward) → robot x, rig Y (up) → robot z; rig units → metres by
  ``s = leg_length / rig_leg`` (amplitude scaling by leg length);
- eq 12: the left foot's stride is put in anti-phase (``+tz * Slgt_L``), as the paper does
  for the up-legs (eq 14/15) and the arms (eq 17/18); its lift uses the anti-phase of eq 8
  (``-sin + delta_f``) so delta_f means the same for both feet;
- foot heights below the ground are stance: clamped at the ground;
- lateral sway of the pelvis in step with the stride (weight over the stance foot);
- steering: ``speed`` scales the stride, ``turn`` yaws the feet (hip yaw) about the
  body's vertical axis (orientation and position), or on 5-DoF legs (no hip yaw) makes
  one stride longer than the other (``stride_turn``), and
  ``side_step`` moves them sideways, both in step with the stride;
- eq 14/15: the up-leg translations move the pelvis: their mean shifts it forward, their
  difference yaws it, ``UpLeg_tY`` sets the hip height;
- eq 3-7 have no spine joint on an 18-DoF biped: ``spine_gain * (StZ_ik - CtZ)`` pitches
  the torso; eq 10/13 pitch each foot by ``toe_gain * Toe_tY`` while it is lifted;
- eq 17-20 move each hand relative to its shoulder.

Outputs are in the pelvis frame (feet) and the torso frame relative to each shoulder
(hands). Floats or numpy arrays, like robot.gait.
"""

from __future__ import annotations

from typing import NamedTuple

from robot.config.params import SPECS, GaitParams
from robot.config.robot import Geometry
from robot.gait import xmath as xm
from robot.gait.xmath import Num, Rot, Vec

HAND_OUT = 0.01  # hands this far outside the shoulder line [m], clear of the torso
ARM_HANG = 0.92  # hanging hand distance below the shoulder / arm length


class BodyTargets(NamedTuple):
    """Targets for one instant.

    r_sole, l_sole: sole points [m] in the pelvis frame; r_foot, l_foot: foot rotations in
    the pelvis frame; r_hand, l_hand: hand points [m] relative to each shoulder centre;
    lift_r, lift_l: foot clearance above the ground [m].
    """

    r_sole: Vec
    r_foot: Rot
    l_sole: Vec
    l_foot: Rot
    r_hand: Vec
    l_hand: Vec
    lift_r: Num
    lift_l: Num


def _yawed(v: tuple[Num, Num, Num], yaw: Num) -> tuple[Num, Num, Num]:
    c, s = xm.cos(yaw), xm.sin(yaw)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


class BodyTrim(NamedTuple):
    """A feedback loop's change of the posture (robot.balance), relative to the feet.

    roll, pitch: extra pelvis rotation [rad] (on a slope the feet follow the ground while
    the body stays upright); r_dx, r_dy, l_dx, l_dy: each foot moved forward / left [m]
    under the pelvis (a feedback loop moves a foot only while it swings, so it lands
    where the body is falling, and keeps it there while it stands); turn: added to the
    gait's ``turn`` [rad/step], the sum kept inside its range; tempo: the gait phase runs
    (1 + tempo) times faster [-] (read by robot.gait.engine, not here); land: 0 walks, 1 keeps
    both feet on the ground (each foot's lift x (1 - land); BodyTargets still report the
    gait's own lift, so a feedback loop knows which foot the gait swings); r_roll,
    r_pitch, l_roll, l_pitch: the pelvis turned further relative to that foot only [rad]
    (a swinging foot kept level with the ground while the torso tilts: position and sole
    turn about the pelvis origin; the pelvis relative to the foot is then
    rz_ry(yaw, pitch + foot pitch) rx(roll + foot roll)); close: over 0.5, a stop
    finishes the swing in progress and closes the feet in the next one (read by
    robot.gait.engine: robot.gait.stop_close; 0: the stride shrinks over ramp_cycles).
    """

    roll: float = 0.0
    pitch: float = 0.0
    r_dx: float = 0.0
    r_dy: float = 0.0
    l_dx: float = 0.0
    l_dy: float = 0.0
    turn: float = 0.0
    tempo: float = 0.0
    land: float = 0.0
    r_roll: float = 0.0
    r_pitch: float = 0.0
    l_roll: float = 0.0
    l_pitch: float = 0.0
    close: float = 0.0


NO_TRIM = BodyTrim()
#: The valid range of ``turn`` [rad/step]; a trimmed turn stays inside it.
TURN_RANGE = (SPECS["turn"].lo, SPECS["turn"].hi)


#: 5-DoF legs (no hip yaw) steer by step length, as a differential drive does: for
#: ``turn`` [rad/step] each foot's stride is shifted by ``turn`` x the half gap of the feet
#: [m] (the right one forward and the left one back in step with the stride, so the right
#: stride grows and the left one shrinks by that much: over the two stances of a cycle the
#: right side of the body moves 4 x turn x half gap farther than the left, which turns a
#: body of that track by ``turn`` per step), at most STRIDE_TURN_MAX x the stride
#: amplitude (Slgt, not the speed: turning on the spot still steps). In physics the body
#: can only yaw by its feet slipping, so which way and how much it turns depends on the
#: robot: in MuJoCo (balance on) the 5-DoF Dynamixel and AX-12 robots turn with the law at
#: a tenth of its rate, the Feetech one against it (docs/gait.md). A heading loop's turn
#: trim is therefore steered this way x ``bal_stride_turn``, the robot's own sign and
#: gain (0 by default: a wrong sign runs away).
STRIDE_TURN_MAX = 0.5


def stride_turn(turn: Num, half_w: Num, stride: Num) -> Num:
    """The stride shift [m] of 5-DoF steering for ``turn`` [rad/step], the feet ``half_w``
    [m] either side of the pelvis, a stride amplitude ``stride`` [m] (>= 0)."""
    d = turn * half_w
    lim = STRIDE_TURN_MAX * stride
    return lim if d > lim else -lim if d < -lim else d


def stride_shift(p: GaitParams, trim_turn: float, half_w: float, s: float) -> float:
    """The stride shift [m] per unit of ``tz`` of 5-DoF legs (``stride_turn``) for the
    asked ``turn`` plus a feedback loop's ``trim_turn`` x ``bal_stride_turn`` [rad/step],
    kept inside TURN_RANGE; the feet ``half_w`` [m] apart, ``s`` metres per rig unit."""
    turn = p.turn
    if trim_turn != 0.0 and p.bal_stride_turn != 0.0:
        turn = min(max(turn + p.bal_stride_turn * trim_turn, TURN_RANGE[0]), TURN_RANGE[1])
    return (0.0 if turn == 0.0
            else stride_turn(turn, half_w, s * 0.5 * (abs(p.Slgt_R) + abs(p.Slgt_L))))


def _per_foot(pelvis_rot: Rot, yaw: Num, pitch: Num, roll: float, foot_roll: float,
              foot_pitch: float) -> Rot:
    """The pelvis's rotation relative to one foot: ``pelvis_rot`` unless the trim turns
    that foot (BodyTrim.r_roll, ...)."""
    if foot_roll == 0.0 and foot_pitch == 0.0:
        return pelvis_rot
    return xm.post_rx(xm.rz_ry(yaw, pitch + foot_pitch), roll + foot_roll)


def scale(g: Geometry, p: GaitParams) -> float:
    """Metres per rig unit."""
    return g.leg_length / p.rig_leg


def body_targets(ch: dict[str, Num], p: GaitParams, g: Geometry, *,
                 amplitude: float = 1.0, leg_yaw: bool = True,
                 trim: BodyTrim = NO_TRIM) -> BodyTargets:
    """Map the paper's channels (robot.gait.channels at ``amplitude``) to body targets.

    leg_yaw: False for 5-DoF legs (no hip yaw): no foot yaws relative to the pelvis, so
    the pelvis yaw of eq 14/15 is left out, the IK's hip yaw is 0, and ``turn`` steers
    by step length instead (``stride_turn``).
    trim: a feedback loop's change of posture (robot.balance), see ``BodyTrim``.
    """
    s = scale(g, p)
    a_delta = amplitude * p.delta_f
    ty, tz = ch["ty"], ch["tz"]
    sin_t = ty - a_delta                # amplitude * sin(theta)
    # Pelvis: height from eq 14/15 tY, forward shift and yaw from their tZ.
    hip_h = p.stance * g.leg_length + g.ankle_height + s * ch["RightUpLeg_tY"]
    px = s * 0.5 * (ch["RightUpLeg_tZ"] + ch["LeftUpLeg_tZ"])
    yaw = s * (ch["RightUpLeg_tZ"] - ch["LeftUpLeg_tZ"]) / g.hip_width if leg_yaw else 0.0
    turn = (p.turn if trim.turn == 0.0
            else min(max(p.turn + trim.turn, TURN_RANGE[0]), TURN_RANGE[1]))
    py = p.sway * (sin_t * xm.cos(p.sway_phase) - tz * xm.sin(p.sway_phase))
    pitch = p.torso_lean + trim.pitch + p.spine_gain * (ch["StZ_ik"] - ch["CtZ"])
    pelvis_rot = xm.rz_ry(yaw, pitch)
    if trim.roll != 0.0:
        pelvis_rot = xm.post_rx(pelvis_rot, trim.roll)

    # Feet in the level frame under the pelvis origin.
    ty_l = 2.0 * a_delta - ty           # eq 8 in anti-phase
    lift_r = xm.maximum(s * ch["RightFoot_tY"], 0.0)
    lift_l = xm.maximum(s * p.Fhgt_L * ty_l, 0.0)
    down = 1.0 - trim.land
    stride_r = ch["RightFoot_tZ"] - p.Fpos_R            # -tz * Slgt_R
    stride_l = -(ch["LeftFoot_tZ"] - p.Fpos_L)          # +tz * Slgt_L (anti-phase)
    half_w = g.hip_width / 2 + p.foot_spread
    r_pos = (s * (p.speed * stride_r + p.Fpos_R),
             -half_w - 0.5 * p.side_step * tz,
             -hip_h + lift_r * down)
    l_pos = (s * (p.speed * stride_l + p.Fpos_L),
             half_w + 0.5 * p.side_step * tz,
             -hip_h + lift_l * down)
    w_r = xm.clip(ty, 0.0, 1.0) * down
    w_l = xm.clip(ty_l, 0.0, 1.0) * down
    yaw_turn = turn if leg_yaw else 0.0
    yaw_r = -0.5 * yaw_turn * tz
    yaw_l = 0.5 * yaw_turn * tz
    r_rot = xm.rz_ry(yaw_r, -p.toe_gain * ch["RightToe_tY"] * w_r)
    l_rot = xm.rz_ry(yaw_l, -p.toe_gain * ch["LeftToe_tY"] * w_l)
    shift = 0.0 if leg_yaw else stride_shift(p, trim.turn, half_w, s)
    if shift != 0.0:
        # 5-DoF steering by step length (STRIDE_TURN_MAX): both feet x - tz * dx, so for
        # a left turn the right stride (-tz * Slgt_R) grows and the left (+tz) shrinks.
        dx = shift * tz
        r_pos = (r_pos[0] - dx, r_pos[1], r_pos[2])
        l_pos = (l_pos[0] - dx, l_pos[1], l_pos[2])
    if yaw_turn != 0.0:
        # Turning: the body rotates about its own vertical axis over the planted foot, so
        # each foot's position turns with its yaw too (otherwise it would have to slip).
        r_pos = _yawed(r_pos, yaw_r)
        l_pos = _yawed(l_pos, yaw_l)

    r_pelvis = _per_foot(pelvis_rot, yaw, pitch, trim.roll, trim.r_roll, trim.r_pitch)
    l_pelvis = _per_foot(pelvis_rot, yaw, pitch, trim.roll, trim.l_roll, trim.l_pitch)
    r_sole = xm.apply_t(r_pelvis, (r_pos[0] - px + trim.r_dx, r_pos[1] - py + trim.r_dy,
                                   r_pos[2]))
    l_sole = xm.apply_t(l_pelvis, (l_pos[0] - px + trim.l_dx, l_pos[1] - py + trim.l_dy,
                                   l_pos[2]))
    r_foot = xm.matmul(xm.transpose(r_pelvis), r_rot)
    l_foot = xm.matmul(xm.transpose(l_pelvis), l_rot)

    # Hands relative to the shoulders (torso frame).
    sa = s * p.arm_scale
    hang = -ARM_HANG * (g.upper_arm + g.forearm)
    r_hand = (sa * (ch["RightArm_tZ"] + ch["RightShoulder_tZ"]), -HAND_OUT,
              hang + sa * (ch["RightArm_tY"] + ch["RightShoulder_tY"]))
    l_hand = (sa * (ch["LeftArm_tZ"] + ch["LeftShoulder_tZ"]), HAND_OUT,
              hang + sa * (ch["LeftArm_tY"] + ch["LeftShoulder_tY"]))
    return BodyTargets(r_sole, r_foot, l_sole, l_foot, r_hand, l_hand, lift_r, lift_l)
