"""Parameter changes asked from other threads (the panel, a gamepad) for the loop's next
tick: a slider's changes, merged and validated when asked, or another preset's parameters
to blend into (robot.gait.blend). The streamer applies them just before a tick."""

from __future__ import annotations

import threading
from collections.abc import Mapping

from robot.config.params import GaitParams
from robot.errors import ConfigError
from robot.loop.source import MotionSource


class PendingParams:
    """What the next tick should change, under one lock."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._changes: dict[str, float] = {}
        self._blend: GaitParams | None = None

    def add(self, source: MotionSource, changes: Mapping[str, float], *, where: str
            ) -> GaitParams:
        """Validate ``changes`` on top of the pending ones (ConfigError, nothing changes);
        the parameters as they will be."""
        params = source.params
        if params is None:
            raise ConfigError(f"{where}: {type(source).__name__} has no parameters to set")
        with self._lock:
            merged = {**self._changes, **changes}
            new = params.replace(merged, where=where)
            self._changes = {k: float(v) for k, v in merged.items()}
        return new

    def blend(self, params: GaitParams) -> None:
        """Switch to another preset's ``params`` (replaces the pending changes)."""
        with self._lock:
            self._changes, self._blend = {}, params

    def apply(self, source: MotionSource) -> None:
        """Give ``source`` what is pending: a blend (``blend_to`` where the source has one,
        else as a change), then the changes asked after it."""
        if not self._changes and self._blend is None:   # the usual tick: nothing asked
            return                 # (a change asked meanwhile is applied at the next tick)
        with self._lock:
            changes, self._changes = self._changes, {}
            blend, self._blend = self._blend, None
        if blend is not None:
            blend_to = getattr(source, "blend_to", None)
            if blend_to is not None:
                blend_to(blend)
            else:
                source.set_params(blend.as_dict(), where="preset")
        if changes:
            source.set_params(changes)
