"""Footsteps on a known staircase (robot.gait.stairs): each swing lands its sole wholly on
one level, at that level's height.

The paper's gait is blind and phase-locked: a foot lands wherever its stride ends, at the
floor's height. ``StairSteps`` follows the gait tick by tick in the floor frame by its own
commands (dead reckoning: a standing foot does not move, so the pelvis is where the
standing feet say; no simulator and no sensor), and when a foot lifts it predicts where the
stride would land it (the gait's own footstep at the end of this swing) and plans:

- a shift ``dx`` [m] of that footstep, the smallest within ``stairs_reach`` that keeps the
  sole ``stairs_margin`` from every riser edge (``StairPlan.placement``), moved in over the
  swing and held while the foot stands;
- the ground under the planned sole (robot.gait.stair_swing): a step up is climbed in the
  first ``RISE_END`` of the swing (the foot lifts first and moves forward high), a step
  down is descended in the swing's last ``1 - DROP_START`` (forward high, then down).

Both soles are moved by their ground less the mean of the two, so the pelvis rides at
the gait's height over the mean of the feet's levels. Offsets are in the level frame
under the pelvis (x forward, z up) [m], turned into the pelvis frame by the torso's pitch.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from robot.config.joint_names import LEG_JOINTS, SIDES
from robot.config.params import GaitParams
from robot.config.robot import Geometry, RobotConfig
from robot.gait import expressions as gait
from robot.gait import xmath as xm
from robot.gait.ik import leg_fk_full
from robot.gait.stair_swing import ground_at, smooth, swing_end
from robot.gait.stairs import StairPlan
from robot.gait.targets import BodyTargets, BodyTrim, body_targets
from robot.gait.xmath import Vec

#: A shifted footstep lands at least this far [m] ahead of the standing foot.
STEP_AHEAD = 0.02
#: ... or beside it (a closing step, at most CLOSE_BEHIND [m] behind it), when it stands
#: within ``stairs_close`` of a riser edge and the lifting foot is more than CLOSE_BEHIND
#: behind it; at most MAX_CLOSINGS closing steps in a row.
CLOSE_BEHIND = 0.01
MAX_CLOSINGS = 2
#: Footsteps shorter than this [m] teach ``reach_gain`` nothing; each longer one moves it
#: ``stairs_learn`` of the way to what it saw, inside GAIN_RANGE.
LEARN_MIN_M = 0.03
GAIN_RANGE = (0.5, 1.2)
@dataclass
class _Foot:
    """One foot's state: where it stands (floor frame), its level and its shift."""

    x: float = 0.0          # floor x of the sole point while it stands [m]
    ground: float = 0.0     # level it stands on [m]
    swinging: bool = False
    theta0: float = 0.0     # phase at lift-off [rad]
    theta1: float = 0.0     # phase at touchdown [rad]
    from_ground: float = 0.0
    to_ground: float = 0.0
    from_dx: float = 0.0    # shift under the pelvis when the current move began [m]
    to_dx: float = 0.0      # ... and when it ends [m]
    now_ground: float = 0.0  # this tick's level under the foot [m]
    now_dx: float = 0.0      # this tick's shift [m]
    placed: bool = True      # its floor x is from a read-back since it landed
    shift: float = 0.0      # how far [m] the swing's footstep is from the gait's
    start_x: float = 0.0    # floor x where the swing began [m]
    aim_x: float = 0.0      # floor x the swing should land at [m]


@dataclass
class StairSteps:
    """The footstep planner of one walk (mutable: one per GaitEngine).

    A footstep put ``dx`` further than the gait's is made by the pelvis: while the foot
    swings, the standing foot is moved ``dx`` further back under the pelvis (the body
    travels the longer step over the standing foot) and the swinging foot returns to the
    gait's own place under the pelvis, so the body is where the gait puts it over the
    new foot when it lands, and the next step starts from there.
    """

    plan: StairPlan
    robot: RobotConfig
    leg_yaw: bool = True
    #: Footstep advance per commanded advance [-] (stairs_odometry: measured on the flat).
    odometry: float = 1.0
    body_x: float = 0.0
    started: bool = False
    feet: tuple[_Foot, _Foot] = field(default_factory=lambda: (_Foot(), _Foot()))
    #: Footsteps planned so far: (right?, floor x of the planned ankle [m], ground [m]).
    steps: list[tuple[bool, float, float]] = field(default_factory=list)
    #: The soles' level-frame x under the pelvis [m] from the last servo read-back
    #: (``measure``), None before the first; ``fresh``: not yet used by ``adjust``.
    measured: tuple[float, float] | None = None
    fresh: bool = False
    pitch: float = 0.0      # the torso pitch [rad] of the last targets
    #: The gait's phase runs this much slower now [-]: 1, or less while a shifted
    #: footstep swings (stairs_slow: the body has further to go over the standing foot).
    rate: float = 1.0
    #: Footstep travel landed per travel sent [-], learned from the read-backs (soft
    #: servos land a long step short); each step is sent that much further.
    reach_gain: float = 1.0
    learn: float = 0.0      # stairs_learn of the walk's parameters [-]
    closings: int = 0       # closing steps in a row so far (_least)

    @property
    def geometry(self) -> Geometry:
        return self.robot.geometry

    def measure(self, q: list[float]) -> None:
        """Take a servo read-back: the joint angles [rad] (the robot's order; a leg joint
        it lacks is 0), under the torso pitch last commanded. Leg odometry:
        the soles under the pelvis where the servos really are (a soft servo lags its
        goal, so a footstep lands short of the commanded one)."""
        names = self.robot.joint_names
        r, lft = (leg_fk_full(self.geometry, s, tuple(
            q[names.index(f"{s}_{j}")] if f"{s}_{j}" in names else 0.0
            for j in LEG_JOINTS))[0] for s in SIDES)
        self.measured = (_level(r, self.pitch)[0], _level(lft, self.pitch)[0])
        self.fresh = True

    def targets(self, ph: gait.Phase, p: GaitParams, amplitude: float,
                trim: BodyTrim) -> BodyTargets:
        """The gait's body targets at phase ``ph`` (the general functions) with both soles
        on their planned footsteps (``adjust``)."""
        ch = gait.channels(ph, p, amplitude=amplitude)
        t = body_targets(ch, p, self.geometry, amplitude=amplitude, leg_yaw=self.leg_yaw,
                         trim=trim)
        self.pitch = float(p.torso_lean + trim.pitch
                           + p.spine_gain * (ch["StZ_ik"] - ch["CtZ"]))
        return self.adjust(t, float(ph.theta), p, amplitude, self.pitch)

    def _gait_x(self, theta: float, p: GaitParams, amplitude: float) -> tuple[float, float]:
        """The gait's own level-frame x [m] of the right and left sole at phase ``theta``."""
        ph = gait.Phase(theta, theta * p.phi, theta * p.k, 0.0, 0.0)
        t = body_targets(gait.channels(ph, p, amplitude=amplitude), p, self.geometry,
                         amplitude=amplitude, leg_yaw=self.leg_yaw)
        return _level(t.r_sole, p.torso_lean)[0], _level(t.l_sole, p.torso_lean)[0]

    def adjust(self, t: BodyTargets, theta: float, p: GaitParams, amplitude: float,
               pitch: float) -> BodyTargets:
        """``t`` (the gait's targets at phase ``theta`` [rad], envelope ``amplitude``,
        torso pitch ``pitch`` [rad]) with both soles moved to their planned footsteps."""
        rel = (_level(t.r_sole, pitch)[0], _level(t.l_sole, pitch)[0])
        lifts = (float(t.lift_r), float(t.lift_l))
        feet = self.feet
        if not self.started:
            self.started = True
            for f, x in zip(feet, rel, strict=True):
                f.x = x * self.odometry
        # Dead reckoning: the pelvis is where the standing feet say: where the servos are
        # (measure) since the last read-back, else where they were sent.
        meas = self.measured
        if meas is not None and self.fresh:
            self.fresh = False
            placed = [f.x - m for f, m in zip(feet, meas, strict=True)
                      if not f.swinging and f.placed]
            if placed:
                self.body_x = sum(placed) / len(placed)
            for f, m in zip(feet, meas, strict=True):
                if not f.swinging and not f.placed and placed:
                    f.x, f.placed = self.body_x + m, True
                    self._learn(f)
        else:
            standing = [f.x - (x + f.now_dx) * self.odometry
                        for f, x in zip(feet, rel, strict=True) if not f.swinging]
            if standing:
                self.body_x = sum(standing) / len(standing)
        for i, (f, lift) in enumerate(zip(feet, lifts, strict=True)):
            if lift > 0.0 and not f.swinging:
                self._lift_off(i, theta, p, amplitude)
            elif lift <= 0.0 and f.swinging:
                f.swinging = False
                f.ground = f.to_ground
                f.x = self.body_x + (rel[i] + f.to_dx) * self.odometry
                f.placed = self.measured is None
        for i, f in enumerate(feet):
            mover = f if f.swinging else feet[1 - i]
            u = (1.0 if not mover.swinging
                 else (theta - mover.theta0) / max(mover.theta1 - mover.theta0, 1e-9))
            f.now_dx = f.from_dx + (f.to_dx - f.from_dx) * smooth(u)
            f.now_ground = ground_at(u, f.from_ground, f.to_ground) if f.swinging else f.ground
        slow = p.stairs_slow
        shift = max([abs(f.shift) for f in feet if f.swinging], default=0.0)
        self.rate = 1.0 / (1.0 + shift / slow) if slow > 0.0 and shift > 0.0 else 1.0
        ref = 0.5 * (feet[0].now_ground + feet[1].now_ground)
        rot = xm.rz_ry(0.0, pitch)
        r_off = xm.apply_t(rot, (feet[0].now_dx, 0.0, feet[0].now_ground - ref))
        l_off = xm.apply_t(rot, (feet[1].now_dx, 0.0, feet[1].now_ground - ref))
        return replace_soles(t, r_off, l_off)

    def _least(self, f: _Foot, other: _Foot, back: float, front: float,
               p: GaitParams) -> float:
        """The rearmost floor x [m] foot ``f`` may land at: STEP_AHEAD past the standing
        foot ``other``, or beside it (a closing step: up to CLOSE_BEHIND behind it) when
        ``f`` is behind it by more than CLOSE_BEHIND and it stands within
        ``stairs_close`` [m] of a riser edge, at most MAX_CLOSINGS in a row (two feet
        that close on each other, each landing a little short, would shuffle before the
        riser for ever).
        Before a riser the closing step puts ``f`` with its toe a margin short of it,
        beside ``other``, and the riser is crossed from two feet side by side: a swing
        of the crossing's length (10 cm up, 7 cm down with 1 cm margins) rather than that
        plus the gait's step."""
        tol = p.stairs_close
        near = tol > 0.0 and not self.plan.stands(
            other.x, back, front, p.stairs_margin + tol, behind=p.stairs_margin_back + tol)
        if near and f.x < other.x - CLOSE_BEHIND and self.closings < MAX_CLOSINGS:
            return other.x - CLOSE_BEHIND
        return other.x + STEP_AHEAD

    def _learn(self, f: _Foot) -> None:
        """Update ``reach_gain`` from a footstep that landed: the travel it made over the
        travel it was aimed at (steps under LEARN_MIN_M are too short to tell)."""
        aimed = f.aim_x - f.start_x
        if aimed < LEARN_MIN_M:
            return
        seen = min(max((f.x - f.start_x) / aimed, GAIN_RANGE[0]), GAIN_RANGE[1])
        self.reach_gain += self.learn * (seen - self.reach_gain)

    def _lift_off(self, i: int, theta: float, p: GaitParams, amplitude: float) -> None:
        """Plan the swing of foot ``i`` (0 right, 1 left) starting now: where it lands,
        how far that is shifted, on what level."""
        f, other = self.feet[i], self.feet[1 - i]
        self.learn = p.stairs_learn
        f.swinging = True
        f.theta0 = theta
        f.theta1 = swing_end(theta, p.delta_f, i == 0)
        ends = self._gait_x(f.theta1, p, amplitude)
        # Where the stride lands it: the standing foot stays, the pelvis moves over it.
        land = other.x + (ends[i] - ends[1 - i] - other.now_dx) * self.odometry
        g = self.geometry
        back = g.foot_length / 2 - g.foot_forward
        front = g.foot_length / 2 + g.foot_forward
        dx = self.plan.placement(land, back, front, p.stairs_margin, p.stairs_reach,
                                 least=self._least(f, other, back, front, p) - land,
                                 behind=p.stairs_margin_back)
        closed = land + dx < other.x + STEP_AHEAD - 1e-6
        self.closings = self.closings + 1 if closed else 0
        # The pelvis ends over the middle of what the new sole rests on: the foot that
        # lands goes ``support`` further back under it (and the standing one with it).
        support = self.plan.support_shift(land + dx, back, front)
        # Sent further by what soft servos are learned to fall short (reach_gain).
        f.start_x, f.aim_x = f.x, land + dx
        dx += (land + dx - f.x) * (1.0 / self.reach_gain - 1.0)
        f.from_ground, f.from_dx, f.to_dx = f.ground, f.now_dx, -support / self.odometry
        f.to_ground = self.plan.under(f.aim_x - back, f.aim_x + front)
        # The standing foot goes back under the pelvis by the shift. Past its leg's reach
        # the IK straightens the leg toward it (robot.gait.ik: counted, ik_unreachable_s):
        # a push-off. Bounding the shift by the reach instead (the footstep landing
        # shorter, or the landing foot taking the rest ahead of the pelvis) fell at the
        # first or second riser on both robots (docs/gait.md, "climb").
        other.from_dx = other.now_dx
        other.to_dx = other.now_dx - (dx + support) / self.odometry
        f.shift = dx
        self.steps.append((i == 0, f.aim_x, f.to_ground))


def _level(v: Vec, pitch: float) -> tuple[float, float, float]:
    """A pelvis-frame vector in the level frame (undo the torso's pitch)."""
    x, y, z = xm.apply(xm.rz_ry(0.0, pitch), (float(v[0]), float(v[1]), float(v[2])))
    return float(x), float(y), float(z)


def replace_soles(t: BodyTargets, r_off: Vec, l_off: Vec) -> BodyTargets:
    """``t`` with each sole moved by its offset (pelvis frame) [m]."""
    rs, ls = t.r_sole, t.l_sole
    return t._replace(r_sole=(rs[0] + r_off[0], rs[1] + r_off[1], rs[2] + r_off[2]),
                      l_sole=(ls[0] + l_off[0], ls[1] + l_off[1], ls[2] + l_off[2]))


