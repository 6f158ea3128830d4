"""Fixed-size statistics of a stream of samples (the loop's tick lateness).

A panel or an animatronics show runs all day: keeping every tick's period error grows by
~23 MB an hour at 200 Hz. ``SampleStats`` keeps the count, the exact maximum and a
uniform random reservoir of at most ``capacity`` samples (Vitter's algorithm R), so the
percentiles are exact while the run fits in the reservoir and an unbiased estimate after.
"""

from __future__ import annotations

import random
from array import array

import numpy as np

#: Reservoir size: exact percentiles for the first 5.4 min at 200 Hz; 512 KiB of floats.
DEFAULT_CAPACITY = 65536


class SampleStats:
    """count, max and percentiles of added samples in O(capacity) memory.

    capacity: reservoir size (>= 1); seed: the reservoir's random stream (reproducible).
    """

    def __init__(self, *, capacity: int = DEFAULT_CAPACITY, seed: int = 0) -> None:
        if capacity < 1:
            raise ValueError(f"capacity: expected >= 1, got {capacity}")
        self.capacity = capacity
        self.count = 0
        self.max = float("-inf")
        self._samples = array("d")
        self._rng = random.Random(seed)

    def add(self, x: float) -> None:
        """Add one sample (hot path: one comparison and an append or a random index)."""
        self.count += 1
        if x > self.max:
            self.max = x
        if len(self._samples) < self.capacity:
            self._samples.append(x)
            return
        j = self._rng.randrange(self.count)
        if j < self.capacity:
            self._samples[j] = x

    @property
    def stored(self) -> int:
        """Samples held in the reservoir (never more than ``capacity``)."""
        return len(self._samples)

    def percentile(self, p: float) -> float:
        """The ``p``-th percentile (0..100) of the samples; 0.0 when there are none."""
        if not self._samples:
            return 0.0
        return float(np.percentile(np.frombuffer(self._samples, dtype=float), p))
