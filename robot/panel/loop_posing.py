"""Posing by hand, in the panel's loop process: release a limb (torque off on it, every
other joint holds where it is), capture its pose as the next keyframe, hand the keyframes
over to be saved. The bus calls run on the loop thread, through the session that owns the
bus (robot.bus.lease); a run started meanwhile forgets the capture."""

from __future__ import annotations

import threading
from typing import Any

from robot.bus.lease import Session
from robot.config.robot import RobotConfig
from robot.errors import BipedError
from robot.motion.keyframes import Sequence
from robot.motion.posing import Capture, limb_joints, limbs
from robot.panel.options import PanelStateError
from robot.run.release import release


class Posing:
    """The keyframes captured by hand for one robot (thread-safe)."""

    def __init__(self, robot: RobotConfig) -> None:
        self.robot = robot
        self._lock = threading.Lock()
        self._capture: Capture | None = None

    def release(self, session: Session, limb: object) -> dict[str, Any]:
        """Loop thread: release ``limb``; a new limb starts a new capture."""
        joints = limb_joints(self.robot, limb)
        try:
            release(self.robot, session, str(limb))
        except BipedError:
            if not session.live:
                raise PanelStateError(f"an emergency stop came first: {limb} not "
                                      "released; torque is off") from None
            raise
        with self._lock:
            if self._capture is None or self._capture.joints != joints:
                self._capture = Capture(self.robot, joints)
        return {"released": str(limb)}

    def captured(self) -> Capture:
        """The capture in progress (PanelStateError before a release)."""
        cap = self._capture
        if cap is None:
            raise PanelStateError("release a limb first (torque off), then move it by hand "
                                  "and capture")
        return cap

    def capture(self, session: Session, cap: Capture, t: float | None) -> dict[str, Any]:
        """Loop thread: read the present pose into ``cap`` at ``t`` [s] (None: the next)."""
        pose = cap.add(session, t=t)
        return {"t": cap.times[-1], "pose": dict(zip(cap.joints, pose, strict=True))}

    def clear(self) -> dict[str, Any]:
        with self._lock:
            self._capture = None
        return {}

    def keyframes(self, name: str) -> Sequence:
        cap = self._capture
        if cap is None or not cap.times:
            raise PanelStateError("no keyframes captured yet")
        return cap.sequence(name)

    def summary(self) -> dict[str, Any]:
        cap = self._capture
        return {"keyframes": len(cap.times) if cap else 0,
                "capture_joints": list(cap.joints) if cap else [],
                "limbs": list(limbs(self.robot))}
