"""A gait engine with a keyframe sequence layered on it (robot.motion.keyframes).

The sequence's joints follow the keyframes at the engine's time; every other joint comes
from the gait. Layered (``walk=True``), the legs walk while the arms and any extra joints
(a head, a waist) play the keyframes; the legs cannot be keyframed then. Standalone
(``walk=False``), the gait stays at its standing pose (amplitude 0) and the sequence may
drive any joint; the engine stops itself at the end of a sequence that does not loop.
Either way it is a motion source (robot.loop.source; standalone, the keyframe player of
`biped play`) and its output goes through the one streaming loop: ramp in to the first
keyframe, clamp, slew, ramp to rest at the end.
"""

from __future__ import annotations

from robot.config.joint_names import LEG_NAMES
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.motion.keyframes import Sequence


class LayeredEngine(GaitEngine):
    """``keyframes``: the sequence (None: the plain gait); ``walk``: legs walk under it."""

    def __init__(self, robot: RobotConfig, params: GaitParams, *,
                 keyframes: Sequence | None = None, walk: bool = True) -> None:
        super().__init__(robot, params)
        self.keyframes = keyframes
        self.walk = walk
        self._index: list[int] = []
        if keyframes is not None:
            legs = [j for j in keyframes.joints if j in LEG_NAMES]
            if walk and legs:
                raise ConfigError(f"{keyframes.source}: {legs[0]}: a sequence layered on the "
                                  "gait drives arms and extra joints only (the legs walk); "
                                  "play it on its own with `biped play`")
            names = robot.joint_names
            self._index = [names.index(j) for j in keyframes.joints]

    def pose(self, *, amplitude: float | None = None) -> list[float]:
        q = super().pose(amplitude=0.0 if not self.walk else amplitude)
        seq = self.keyframes
        if seq is not None:
            for i, v in zip(self._index, seq.at(self.time).tolist(), strict=True):
                q[i] = min(max(v, self._lo[i]), self._hi[i])
        return q

    @property
    def finished(self) -> bool:
        """A standalone sequence that does not loop has played to its end."""
        seq = self.keyframes
        return (not self.walk and seq is not None and not seq.loop
                and self.time >= seq.duration - 1e-12)

    def tick(self, dt: float) -> list[float]:
        if self.walk:
            return super().tick(dt)
        if self.finished:
            self.stop()
        self.time += dt
        return self.pose()
