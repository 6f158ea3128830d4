"""How `biped tune` shows its progress: a tqdm bar on a terminal; on anything else (a log
file, CI, a pipe) one plain line per finished trial, with the best score so far, so a
redirected run is never silent."""

from __future__ import annotations

import sys
from typing import TextIO

from tqdm import tqdm


class TrialProgress:
    """``total`` trials; ``quiet`` (--json): show nothing; ``stream``: where (stderr)."""

    def __init__(self, total: int, *, quiet: bool = False, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stderr
        self.total = total
        self.done = 0
        self.quiet = quiet
        tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.bar = (tqdm(total=total, desc="trials", unit="trial", file=self.stream)
                    if tty and not quiet else None)

    def __call__(self, done: int, best: float | None = None) -> None:
        """``done`` trials have finished (``best``: the best score so far)."""
        if done <= self.done:
            return
        if self.bar is not None:
            self.bar.update(done - self.done)
            if best is not None:
                self.bar.set_postfix(best=f"{best:.3f}")
        elif not self.quiet:
            for n in range(self.done + 1, done + 1):
                tail = f", best score {best:.3f}" if best is not None and n == done else ""
                print(f"trial {n}/{self.total} finished{tail}", file=self.stream, flush=True)
        self.done = done

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
