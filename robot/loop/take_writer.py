"""Recording a take as the run goes (the file format: robot.motion.takes): a tick observer
of the loop, like the CSV/JSONL recorder (robot.loop.recorder), written the same way
(robot.files.atomic.OutputFile): renamed into place when the run has closed if it
ticked, else removed (an older take of that name stays as it was)."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from robot.errors import ConfigError
from robot.files.atomic import OutputFile
from robot.loop.telemetry import Telemetry
from robot.motion.takes import SUFFIX, TakeHeader, is_take


class TakeWriter:
    """Writes a take as the run goes: ``open()`` writes the header, ``event()`` a timeline
    line (from the loop thread, via ``robot.motion.scripted.RecordingEngine``), and calling it with
    the loop's telemetry writes the tick. A failed write (disk full) is kept and raised at
    the next tick, so the streamer ends the run as an observer fault (ramp out, torque off).
    ``show_time``: a chased show's time (robot/timecode/chased.py): each tick's ``t``, from
    the first tick it is known."""

    def __init__(self, path: str | Path, header: TakeHeader, *,
                 show_time: Callable[[], float | None] | None = None) -> None:
        self.path = Path(path)
        self.show_time = show_time
        if not is_take(self.path):
            raise ConfigError(f"{path}: a take file name ends in {SUFFIX}")
        self.header = header
        self._file: OutputFile | None = None
        self._last_tick = -1
        self._t0: float | None = None
        self.error: str | None = None
        self.ticks = 0

    def open(self) -> TakeWriter:
        try:
            self._file = OutputFile(self.path).open()
        except OSError as e:
            raise ConfigError(f"--record {self.path}: cannot write it: "
                              f"{e.strerror or e}") from None
        self._line(self.header.as_json())
        return self

    def _line(self, obj: Mapping[str, Any]) -> None:
        if self._file is None:
            return
        try:
            self._file.write(json.dumps(obj) + "\n")
        except OSError as e:
            self.error = self.error or f"{self.path}: {e.strerror or e}"

    def event(self, gait_tick: int, **what: Any) -> None:
        self._line({"gait_tick": gait_tick, "t": gait_tick / self.header.rate_hz, **what})

    def __call__(self, tel: Telemetry) -> None:
        if self.error is not None:
            raise OSError(self.error)
        if self._file is None or tel.tick == self._last_tick or not tel.q_cmd:
            return
        self._last_tick = tel.tick
        if self.show_time is not None:          # a chased show: t is its show time, from
            shown = self.show_time()            # the first tick the timecode was heard
            if shown is None:
                return
            self.ticks += 1
            self._line({"tick": tel.tick, "t": round(shown, 9), "state": tel.state,
                        "q": tel.q_cmd, **({"present": tel.q_present}
                                           if tel.fresh and tel.q_present else {})})
            return
        if self._t0 is None:
            self._t0 = tel.t
        self.ticks += 1
        line: dict[str, Any] = {"tick": tel.tick, "t": tel.t - self._t0, "state": tel.state,
                                "q": tel.q_cmd}
        if tel.fresh and tel.q_present:         # read back this tick (biped sim-gap), and
            line["present"] = tel.q_present     # when: the reply was in [s, the t clock:
            line["present_t"] = tel.t_read - self._t0   # the sim's on the sim bus]
        self._line(line)

    def close_quietly(self) -> str | None:
        """Rename the take into place if a tick was recorded, else remove it; the first
        failed write as one line, or None."""
        if self._file is not None:
            file, self._file = self._file, None
            try:
                if self.ticks:
                    file.commit()
                else:
                    file.discard()
            except OSError as e:
                self.error = self.error or f"{self.path}: {e.strerror or e}"
        return self.error
