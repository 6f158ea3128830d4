"""The gait at many instants at once: numpy arrays through the general functions.

``curves`` evaluates channels → body targets → IK (robot.gait.expressions, .targets,
.ik) on arrays of times, in cache-sized chunks. The chunks are independent (every
operation is elementwise), so they are spread over threads: numpy releases the GIL in
its loops, and each chunk writes only its own columns of the output, so the result is
the same bits whatever the chunk size or the number of threads.

A chunk's temporaries (some 10 MB) are freed at its end, and glibc then hands the heap's
free top back to the OS (past 128 kB): the next chunk page-faults all of it in again,
about 200 000 faults per million frames, half the time of the evaluation. A library
function does not change the process's allocator behind its caller's back, so this is
left to the user: glibc's own tunable ``MALLOC_TOP_PAD_=33554432`` (32 MB kept at the heap
top) in the environment of a long batch evaluation removes those faults.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import numpy.typing as npt

from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.gait import expressions as gait
from robot.gait.ik import Reach, arm_ik, arm_reach
from robot.gait.ik_chain import chain_leg_ik, knee_span
from robot.gait.targets import BodyTargets, body_targets
from robot.gait.xmath import Num

#: Frames per chunk: a chunk's temporaries stay in the CPU's caches.
CHUNK = 16384
def spans(robot: RobotConfig) -> tuple[Reach, Reach, Reach | None, Reach | None]:
    """What the right and left knee and elbow limits let each leg and arm span (ik.Reach;
    no arms: None)."""
    def limits(name: str) -> tuple[float, float]:
        j = robot.joint(name)
        return j.min_rad, j.max_rad
    g = robot.geometry
    r_leg, l_leg = (knee_span(leg, *limits(f"{leg.side}_knee")) for leg in robot.legs)
    if not robot.has_arms:
        return r_leg, l_leg, None, None
    return r_leg, l_leg, arm_reach(g, *limits("r_elbow")), arm_reach(g, *limits("l_elbow"))


def solve(t: BodyTargets, robot: RobotConfig) -> tuple[list[Num], Num]:
    """IK for every joint of ``robot`` (its joint order) within what its knee and elbow
    limits let the chains span (``spans``), and a reachable flag. The legs are
    ``robot.legs`` (robot.gait.ik_chain: the box model's closed form for simple chains)."""
    g = robot.geometry
    r_leg, l_leg, r_arm, l_arm = spans(robot)
    r_chain, l_chain = robot.legs
    r = chain_leg_ik(r_chain, t.r_sole, t.r_foot, span=r_leg)
    lft = chain_leg_ik(l_chain, t.l_sole, t.l_foot, span=l_leg)
    q: list[Num] = [*r.q, *lft.q]
    ok = r.reachable & lft.reachable
    if robot.has_arms:
        ra = arm_ik(g, t.r_hand, span=r_arm)
        la = arm_ik(g, t.l_hand, span=l_arm)
        q += [*ra.q, *la.q]
        ok = ok & ra.reachable & la.reachable
    layout = robot.layout
    if layout is not None:   # 5-DoF legs, extra joints held at fixed angles
        q = [q[i] if i >= 0 else fixed for i, fixed in layout]
    return q, ok


def default_workers() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def curves(robot: RobotConfig, p: GaitParams, times: npt.NDArray[np.float64], *,
           chunk: int = CHUNK, with_channels: bool = True, workers: int | None = None
           ) -> tuple[dict[str, npt.NDArray[np.float64]], npt.NDArray[np.float64]]:
    """Channels and joint angles [rad] (n_joints, n), clamped to the joint limits, over
    ``times`` [s] at full amplitude and constant parameters ``p``. ``with_channels=False``
    returns an empty channel dict; ``workers``: threads (default: one per CPU)."""
    times = np.asarray(times, dtype=float)
    n = times.shape[0]
    names = gait.CHANNELS if with_channels else ()
    out_ch = {name: np.empty(n) for name in names}
    out_q = np.empty((len(robot.joints), n))
    lo = np.array([j.min_rad for j in robot.joints])[:, None]
    hi = np.array([j.max_rad for j in robot.joints])[:, None]
    leg_yaw = robot.has_hip_yaw

    def one(start: int) -> None:
        sl = slice(start, min(start + chunk, n))
        t = times[sl]
        ch = gait.curves(t, p) if with_channels else gait.channels(gait.phase_at(t, p), p)
        q, _ = solve(body_targets(ch, p, robot.geometry, leg_yaw=leg_yaw), robot)
        for name in names:
            out_ch[name][sl] = ch[name]
        block = out_q[:, sl]
        for j, v in enumerate(q):
            block[j] = v
        np.clip(block, lo, hi, out=block)

    starts = range(0, n, chunk)
    threads = min(len(starts), default_workers() if workers is None else workers)
    if threads <= 1:
        for start in starts:
            one(start)
    else:
        with ThreadPoolExecutor(threads, thread_name_prefix="gait-curves") as pool:
            for _ in pool.map(one, starts):  # re-raises a chunk's exception
                pass
    return out_ch, out_q


def sole_targets(robot: RobotConfig, p: GaitParams, times: npt.NDArray[np.float64]
                 ) -> npt.NDArray[np.float64]:
    """The right and left sole targets (2, n, 3) [m, pelvis frame] the IK of ``curves``
    solves for over ``times`` [s] (before the joint limits clamp the angles)."""
    times = np.asarray(times, dtype=float)
    t = body_targets(gait.curves(times, p), p, robot.geometry, leg_yaw=robot.has_hip_yaw)
    return np.stack([np.stack([np.broadcast_to(np.asarray(v, float), times.shape)
                               for v in sole], axis=1) for sole in (t.r_sole, t.l_sole)])
