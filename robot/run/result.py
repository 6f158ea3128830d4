"""What a run returns: the loop's statistics, the bus's metrics (simulation), the
recording's fate and the exit code, as one frozen value."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from robot.loop.telemetry import LoopStats


@dataclass(frozen=True)
class RunResult:
    """stats: the loop's; wall_s: wall time from opening to closing the run [s]; seconds:
    the source's time limit [s] (None: none); metrics: the bus's summary of the run (the
    simulated bus: distance, fall, effort, world; None: a bus that does not watch its
    runs); record_error: the first failed write of the recording as one line (None: none,
    or no recording); exit_code: 0 completed, 1 a fault or a failed recording, 128 + the
    signal that stopped it (the CLI's exit codes)."""

    stats: LoopStats
    wall_s: float
    seconds: float | None
    metrics: Mapping[str, Any] | None
    record_error: str | None
    exit_code: int

    @property
    def realtime_factor(self) -> float:
        """Loop time per wall time (the simulation runs faster than real time: > 1)."""
        return self.stats.duration_s / self.wall_s if self.wall_s > 0 else 0.0

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, as `biped walk --json` prints it after its header (robot, gait, bus,
        seconds, balance): the metrics, the loop, the recording error if any, the exit
        code."""
        s = self.stats
        out: dict[str, Any] = dict(self.metrics or {})
        out.update({
            "ticks": s.ticks, "rate_hz": s.rate_hz, "achieved_hz": s.achieved_hz,
            "period_error_p50_ms": s.period_error_p50_ms,
            "period_error_p99_ms": s.period_error_p99_ms,
            "period_error_max_ms": s.period_error_max_ms,
            "overruns": s.overruns, "bus_errors": s.bus_errors,
            "realtime_factor": self.realtime_factor,
            "stop_reason": s.stop_reason, "fault": s.fault, "holding": s.holding,
            "torque": s.torque,
        })
        if self.record_error is not None:
            out["record_error"] = self.record_error
        out["exit_code"] = self.exit_code
        return out


#: What the CLI says of the servos' torque at the end, by LoopStats.torque: only what the
#: bus confirmed (docs/hardware.md, "What happens when").
TORQUE_WORDS = {
    "on": "holding, torque ON",
    "off": "torque off",
    "sent": "torque-off sent, not confirmed (the servos stopped answering)",
    "unknown": "torque state UNKNOWN: nothing could be sent (the port failed); the servos "
               "may still hold torque (docs/hardware.md, \"When the host vanishes\")",
    "untouched": "stopped before it started: nothing moved, torque untouched",
}


def torque_words(stats: LoopStats) -> str:
    """The servos' torque at the end of a run as the CLI says it (``TORQUE_WORDS``)."""
    return TORQUE_WORDS.get(stats.torque, f"torque {stats.torque}")
