"""Log a kind of problem once, count every time it happens: a controller sending a wrong
address 10,000 times a second writes one line, not 10,000 (and never slows for it)."""

from __future__ import annotations

import logging
import threading
from collections import Counter

#: Distinct kinds kept at most (an address space is small; a sender of random addresses
#: lands in the one kind "address").
MAX_KINDS = 256


class OnceLog:
    """``note(kind, line)``: the first time ``kind`` is seen, ``line`` is logged as a
    warning on ``logger``; every time it is counted (``counts``)."""

    def __init__(self, logger: logging.Logger) -> None:
        self.log = logger
        self.counts: Counter[str] = Counter()
        self._lock = threading.Lock()

    def note(self, kind: str, line: str) -> None:
        with self._lock:
            first = kind not in self.counts
            if first and len(self.counts) >= MAX_KINDS:
                kind, first = "other", "other" not in self.counts
            self.counts[kind] += 1
        if first:
            self.log.warning("%s (ignored; further ones of this kind are only counted)", line)

    def summary(self) -> dict[str, int]:
        with self._lock:
            return dict(self.counts)
