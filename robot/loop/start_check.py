"""The check before a run takes torque: is every joint where the loop may command it?"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from robot.bus.servo_map import ServoMap
from robot.errors import StartRefused


def check_inside_limits(smap: ServoMap, present: npt.NDArray[np.float64], *,
                        tolerance: float | npt.NDArray[np.float64],
                        source: str) -> npt.NDArray[np.float64]:
    """``present`` [rad] clamped to the joint limits; StartRefused (naming the joint, how far
    out it is and the fix) if a joint is further outside than ``tolerance`` [rad] (scalar or
    per joint): its first goal would jump it."""
    inside = smap.clamp(present)
    beyond = np.abs(present - inside) - tolerance
    if (beyond > 0).any():
        i = int(np.argmax(beyond))
        name, q, lim = smap.names[i], float(present[i]), float(inside[i])
        side = "max_rad" if q > lim else "min_rad"
        others = int((beyond > 0).sum()) - 1
        more = f" (and {others} more joint{'s' * (others > 1)})" if others else ""
        raise StartRefused(
            f"refusing to start: {name} (servo id {smap.ids[i]}) is at {q:.3f} rad, "
            f"{abs(q - lim):.3f} rad ({np.degrees(abs(q - lim)):.1f} deg) beyond its "
            f"{side} {lim:.3f}{more}; move it inside its limits by hand with torque off "
            f"(`biped torque off`), or check its zero_ticks, sign and limits in {source}")
    return inside
