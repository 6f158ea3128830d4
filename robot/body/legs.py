"""A leg as the IK sees it: where its axes are, in the pelvis frame, at the zero pose.

The zero pose is the project's (docs/robots.md): legs straight and hanging, feet flat,
every joint at 0 rad in the project's convention. A model whose own zero has bent knees
or tilted feet is brought to this one by per-joint offsets (robot/body/roles.py); there,
the axes of a leg are, with the right-hand rule and REP-103 axes (x forward, y left, z up):

- hip yaw about +z, a vertical line through ``yaw_axis`` = (x, y) [m] (absent on 5-DoF
  legs without hip yaw);
- hip roll about +x, a line through ``hip`` = (x_p, y_r, z_r) [m];
- hip pitch about +y, ``roll_drop`` [m] below the roll axis (the pitch axis passes through
  (x_p, *, z_r - roll_drop)): a roll axis off the pitch axis;
- knee about +y, ``thigh`` [m] below the hip pitch axis; ankle pitch about +y, ``shin`` [m]
  below the knee; the three pitch axes are parallel, and the leg's parts shift sideways
  along them by ``lateral`` [m] in all (hip roll axis to ankle roll axis, +y);
- ankle roll about +x, ``ankle_drop`` [m] below the ankle pitch axis (absent on 5-DoF legs
  without ankle roll);
- the sole point, ``sole`` [m] from the ankle roll point (x_p, y_r + lateral, z_ankle_roll)
  in the foot frame (the box model's: (0, 0, -ankle_height)).

``order`` says which hip joint the pelvis carries: "yaw_roll" (yaw first, the usual),
or "roll_yaw" (roll first, then yaw: some 5-DoF legs). ``knee_back`` says which way the
knee bends: False (the usual) forward, knee angles >= 0 (the shin swings back, the knee
points forward); True backward, knee angles <= 0 (the thigh swings back and the shin
forward as the leg crouches: a bird's, or the Open Duck Mini's, whose hip pitch lets the
thigh swing 0.52 rad forward but 1.22 rad back). The IK takes that branch. ``fk`` below is the definition the
IK inverts (robot/gait/ik_chain.py); the test oracle is MuJoCo on the model's own file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Vec3 = tuple[float, float, float]
Array = npt.NDArray[np.float64]
ORDERS = ("yaw_roll", "roll_yaw")


@dataclass(frozen=True)
class LegChain:
    """One leg's kinematics (see the module docstring) [m]. side: "r" or "l"."""

    side: str
    hip: Vec3
    thigh: float
    shin: float
    sole: Vec3
    yaw_axis: tuple[float, float] | None = None
    roll_drop: float = 0.0
    lateral: float = 0.0
    ankle_drop: float = 0.0
    has_ankle_roll: bool = True
    order: str = "yaw_roll"
    knee_back: bool = False

    @property
    def has_yaw(self) -> bool:
        return self.yaw_axis is not None

    @property
    def simple(self) -> bool:
        """True when every axis meets where the box model says: the hip's three axes in
        one point, the ankle's two in one, the sole straight below it, no sideways
        offset, the ankle roll there, yaw (if any) first, the knee bending forward:
        robot/gait/ik.py's closed form of the box model, bit for bit (without hip yaw it
        solves as if there were one and the yaw is dropped, as for the box model's 5-DoF
        legs)."""
        hx, hy, _ = self.hip
        yaw_on_hip = self.yaw_axis is None or self.yaw_axis == (hx, hy)
        return (yaw_on_hip and self.roll_drop == 0.0 and self.lateral == 0.0
                and self.ankle_drop == 0.0 and self.sole[0] == 0.0 and self.sole[1] == 0.0
                and self.has_ankle_roll and self.order == "yaw_roll" and not self.knee_back)

    @property
    def pitch_point(self) -> Vec3:
        """The hip pitch axis at the roll axis's y, at the zero pose [m]."""
        return (self.hip[0], self.hip[1], self.hip[2] - self.roll_drop)

    @property
    def ankle_height(self) -> float:
        """Ankle pitch axis to the sole, straight down at the zero pose [m]."""
        return self.ankle_drop - self.sole[2]

    def zero_sole(self) -> Vec3:
        """The sole point at the zero pose [m]."""
        x, y, z = self.hip
        return (x + self.sole[0], y + self.lateral + self.sole[1],
                z - self.roll_drop - self.thigh - self.shin - self.ankle_drop + self.sole[2])


def _rx(a: float) -> Array:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(a: float) -> Array:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rz(a: float) -> Array:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def fk(leg: LegChain, q: tuple[float, float, float, float, float, float]
       ) -> tuple[Array, Array]:
    """The sole point [m] and the foot's rotation in the pelvis frame at leg angles ``q``
    = (hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll) [rad] (a joint the leg
    lacks must be 0)."""
    yaw, roll, pitch, knee, ankle_pitch, ankle_roll = q
    hip = np.asarray(leg.hip, float)
    yaw_point = hip if leg.yaw_axis is None else np.array([*leg.yaw_axis, hip[2]])
    drop = np.array([0.0, 0.0, -leg.roll_drop])
    if leg.order == "yaw_roll":
        r1 = _rz(yaw) @ _rx(roll)
        h_pitch = yaw_point + _rz(yaw) @ (hip - yaw_point) + r1 @ drop
    else:
        yaw_now = hip + _rx(roll) @ (yaw_point - hip)
        r1 = _rx(roll) @ _rz(yaw)
        h_pitch = yaw_now + r1 @ (hip - yaw_point + drop)
    r3 = r1 @ _ry(pitch)
    knee_p = h_pitch + r3 @ np.array([0.0, 0.0, -leg.thigh])
    r4 = r3 @ _ry(knee)
    ankle_p = knee_p + r4 @ np.array([0.0, leg.lateral, -leg.shin])
    r5 = r4 @ _ry(ankle_pitch)
    ankle_r = ankle_p + r5 @ np.array([0.0, 0.0, -leg.ankle_drop])
    r6 = r5 @ _rx(ankle_roll)
    return ankle_r + r6 @ np.asarray(leg.sole, float), r6
