"""What the panel's runs are made of: their loop options, the engine factory of a run,
and the error for a request that does not fit the loop's state."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from robot.config.params import GaitParams
from robot.errors import BipedError
from robot.gait.engine import GaitEngine
from robot.loop.source import Feedback

#: Builds a run's engine from the current parameters (a recording, a replay, keyframes).
EngineFactory = Callable[[GaitParams], GaitEngine]


class PanelStateError(BipedError):
    """The request does not fit the loop's state (e.g. start while running)."""


@dataclass(frozen=True)
class LoopOptions:
    """rate_hz: control rate [Hz]; read_every: read back every N ticks; hold: keep torque
    on at the rest pose after a stop; feedback: builds each run's feedback stage (balance)
    for its engine, after the bus is open (None: open loop)."""

    rate_hz: float = 200.0
    read_every: int = 10
    hold: bool = False
    feedback: Callable[[GaitEngine], Feedback | None] | None = None


#: The options of a panel given none.
DEFAULT_OPTIONS = LoopOptions()
