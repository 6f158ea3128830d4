"""Per-tick recording of a run to CSV or JSON Lines (chosen by the file extension).

The file is written under a temporary name and renamed when the run has closed
(robot.files.atomic.OutputFile): a run that never ticked (the bus did not open, the
start was refused) leaves whatever was at the path untouched; one that ended (completed,
Ctrl-C, a fault) leaves every whole row it recorded.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any

from robot.config.model_angles import ModelAngles
from robot.errors import ConfigError
from robot.files.atomic import OutputFile
from robot.loop.streamer import Telemetry

FORMATS = (".csv", ".jsonl")


class Recorder:
    """Writes time since the first tick [s], commanded and present joint positions, loop
    timing, temperatures and loads (present values only on read-back ticks, blank / null
    otherwise), and the joints held at a limit that tick (``clamped``: names separated by
    spaces, blank when none). ``model``: an imported robot's joints in its model's terms
    (robot/config/model_angles.py): the commanded and present angles again, as
    ``model_cmd_<model joint>`` and ``model_present_<model joint>`` [rad, the model's
    convention], after the rest."""

    def __init__(self, path: str | Path, joint_names: tuple[str, ...],
                 ids: tuple[int, ...], *, model: ModelAngles | None = None) -> None:
        self.path = Path(path)
        if self.path.suffix not in FORMATS:
            raise ConfigError(f"--record {path}: unknown format {self.path.suffix!r}; "
                              f"valid: {', '.join(FORMATS)}, .mcap, or .take.jsonl (a take for biped "
                              "play)")
        self.names = joint_names
        self.ids = ids
        self.model = model
        self._file: OutputFile | None = None
        self._row = io.StringIO()
        self._csv: Any = None  # a csv.writer on _row (its type is private to the csv module)
        self._last_tick = -1
        self._t0: float | None = None
        self.error: str | None = None  # the first failed write, one line (e.g. disk full)

    def header(self) -> list[str]:
        cols = ["t", "state", "tick", "period_error_ms", "overruns", "amplitude"]
        cols += [f"cmd_{n}" for n in self.names] + [f"present_{n}" for n in self.names]
        cols += [f"temp_{n}" for n in self.names] + [f"load_{n}" for n in self.names]
        cols.append("clamped")
        if self.model is not None:
            cols += [f"model_cmd_{n}" for n in self.model.names]
            cols += [f"model_present_{n}" for n in self.model.names]
        return cols

    def open(self) -> Recorder:
        """Create the temporary file (ConfigError naming the path if it cannot be)."""
        try:
            self._file = OutputFile(self.path).open()
        except OSError as e:
            raise ConfigError(f"--record {self.path}: cannot write it: "
                              f"{e.strerror or e}") from None
        if self.path.suffix == ".csv":
            self._csv = csv.writer(self._row)
            self._write_row(self.header())
        return self

    def _write_row(self, row: list[Any]) -> None:
        assert self._file is not None
        self._csv.writerow(row)
        text = self._row.getvalue()
        self._row.seek(0)
        self._row.truncate()
        self._file.write(text)

    def close(self) -> None:
        """Rename the file into place if a tick was recorded, else remove it (OSError if
        a write failed: the file keeps the rows before it)."""
        if self._file is not None:
            file, self._file = self._file, None
            if self._last_tick >= 0:
                file.commit()
            else:
                file.discard()

    def close_quietly(self) -> str | None:
        """Close; the error as one line if the last writes failed (e.g. disk full)."""
        try:
            self.close()
        except OSError as e:
            self.error = self.error or f"{self.path}: {e.strerror or e}"
        return self.error

    def __call__(self, tel: Telemetry) -> None:
        if self._file is None or tel.tick == self._last_tick:
            return
        try:
            self._write(tel)
        except OSError as e:
            self.error = self.error or f"{self.path}: {e.strerror or e}"
            raise

    def _write(self, tel: Telemetry) -> None:
        assert self._file is not None
        self._last_tick = tel.tick
        if self._t0 is None:
            self._t0 = tel.t
        fresh = tel.fresh and tel.q_present is not None
        present = tel.q_present if fresh and tel.q_present else [math.nan] * len(self.names)
        servo = tel.servo if fresh else {}
        temps = [servo[i].temperature if i in servo else None for i in self.ids]
        loads = [servo[i].load if i in servo else None for i in self.ids]
        row = [tel.t - self._t0, tel.state, tel.tick, tel.period_error_ms, tel.overruns, tel.amplitude,
               *tel.q_cmd, *present, *temps, *loads, " ".join(tel.clamped) or None]
        if self.model is not None:
            row += [*self.model.values(tel.q_cmd).tolist(),
                    *self.model.values(present).tolist()]
        if self._csv is not None:
            self._write_row(["" if v is None or (isinstance(v, float) and math.isnan(v))
                             else v for v in row])
        else:
            rec = {k: (None if isinstance(v, float) and math.isnan(v) else v)
                   for k, v in zip(self.header(), row, strict=True)}
            self._file.write(json.dumps(rec) + "\n")
