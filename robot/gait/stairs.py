"""A staircase the user describes (the gait's ``stairs_*`` parameters): its ground height
and where a sole may stand on it.

Floor frame: x forward from the start pose's ankles, z up from the floor. ``count``
steps of ``rise`` up, the first riser at ``x0``, each tread ``tread`` deep, a landing
``landing`` deep at the top, and as many steps down, each tread as deep. The numbers come
from the user (a gait file or ``--set``), never from a simulator: on a real robot they are
what was measured with a ruler. A sole is "on" the stairs when it is wholly on one level
and at least a margin from every riser edge; a sole across an edge rests on the nosing
with its ankle behind it, which is what the blind gait falls on (docs/gait.md, "climb").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.config.params import GaitParams


@dataclass(frozen=True)
class StairPlan:
    """The staircase: ``count`` steps ``rise`` [m] high, the first riser ``x0`` [m] ahead,
    treads ``tread`` [m] deep, a landing ``landing`` [m] deep between the flights."""

    rise: float
    count: int
    tread: float
    x0: float
    landing: float

    @classmethod
    def of(cls, p: GaitParams) -> StairPlan | None:
        """The plan the parameters describe, None when they describe none (no count or
        no rise)."""
        n = round(p.stairs_count)
        if n <= 0 or p.stairs_rise <= 0.0:
            return None
        return cls(p.stairs_rise, n, p.stairs_tread, p.stairs_x0, p.stairs_landing)

    def edges(self) -> tuple[float, ...]:
        """x of every riser [m], in order: the ``count`` up, then the ``count`` down."""
        up = [self.x0 + k * self.tread for k in range(self.count)]
        top_end = up[-1] + self.landing
        down = [top_end + k * self.tread for k in range(self.count)]
        return (*up, *down)

    def ground(self, x: float) -> float:
        """Ground height [m] at ``x`` [m] (a point exactly on a riser counts as the lower
        side)."""
        edges = self.edges()
        n = self.count
        ups = sum(1 for e in edges[:n] if x > e)
        downs = sum(1 for e in edges[n:] if x > e)
        return (ups - downs) * self.rise

    def under(self, heel: float, toe: float) -> float:
        """The highest ground [m] under a sole from ``heel`` to ``toe`` [m] (heel <= toe):
        where it rests."""
        return max([self.ground(heel), self.ground(toe)]
                   + [self.ground(e + 1e-9) for e in self.edges() if heel < e < toe])

    def stands(self, ankle: float, back: float, front: float, margin: float, *,
               behind: float | None = None) -> bool:
        """True when a level sole from ``ankle - back`` to ``ankle + front`` [m] rests on
        the level under its ankle, with ``margin`` [m] to spare ahead and ``behind`` [m]
        (default: ``margin``) behind: no riser edge that close to the ankle, and the
        ground under the ankle the highest under the sole lengthened by as much at each
        end (a sole may overhang a lower level, heel past a riser up or toe past a riser
        down; it may not rest on a nosing ahead of or behind its ankle). A footstep that
        lands short needs the margin behind."""
        b = margin if behind is None else behind
        if any(ankle - b < e < ankle + margin for e in self.edges()):
            return False
        return self.ground(ankle) >= self.under(ankle - back - b, ankle + front + margin)

    def support_shift(self, ankle: float, back: float, front: float) -> float:
        """How far [m] the middle of the part of a sole that rests on the level under its
        ankle is ahead of the sole's middle: a heel overhanging a riser up moves it
        forward, a toe overhanging a riser down moves it back (0: the whole sole rests)."""
        heel, toe = ankle - back, ankle + front
        lo = max([heel] + [e for e in self.edges() if heel < e <= ankle])
        hi = min([toe] + [e for e in self.edges() if ankle < e < toe])
        return (lo + hi) / 2 - (heel + toe) / 2

    def placement(self, ankle: float, back: float, front: float, margin: float,
                  reach: float, *, least: float = -math.inf,
                  behind: float | None = None) -> float:
        """The smallest shift [m] (+ forward) within ``reach`` [m] either way, and not
        less than ``least`` [m], that makes the sole of ``stands`` stand; 0 when it
        stands already or no such shift makes it stand. (``least`` keeps a step from
        going back beside the standing foot: two feet that both step back from a riser
        would never cross it.) The candidates: the ankle ``margin`` either side of an
        edge, the toe or the heel ``margin`` short of one."""
        b = margin if behind is None else behind
        shifts = [0.0]
        for e in self.edges():
            shifts += [e + b - ankle, e - margin - ankle, e - front - margin - ankle,
                       e + back + b - ankle]
        for dx in sorted(shifts, key=abs):
            if abs(dx) > reach:
                break
            if dx != 0.0 and dx < least:
                continue
            # A hair further, so rounding cannot leave the sole on the limit.
            d = dx + (1e-9 if dx > 0 else -1e-9 if dx < 0 else 0.0)
            if self.stands(ankle + d, back, front, margin, behind=b):
                return d
        return 0.0
