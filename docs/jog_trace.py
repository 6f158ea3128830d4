"""A per-tick trace of one simulated walk, for reading how a run falls (issue 22, the `jog`
quick-suite traces in docs/robustness.md): the walk is `biped walk --stop-on-fall` with
the preset's own gains and balance on, and every few control ticks it prints, read from
MuJoCo and from the gait engine:

    t       sim time [s] (the gait time is about 0.3-0.4 s less: the ramp to the start pose)
    th      the gait phase theta mod 2 pi [rad] (the left foot swings for theta in pi..2 pi)
    liftR/L the gait's commanded foot lift [m]
    roll    torso roll [deg] (+: right side down); pitch: torso pitch [deg] (+: nose down)
    tx ty tz  torso position [m]; rfx.. lfz: the sole geoms' centres [m] (on the floor z 9 mm)
    rC lC   what each sole touches: F the floor, B:name a bump box, - nothing
    rdx..ldy  the balance stage's step offsets [m]; tempo: phase rate - 1 (-1: the gait
            stands still); land: 1 both feet are set down (the brace)

Run: ``MUJOCO_GL=egl nice -n 5 .venv/bin/python docs/jog_trace.py biped18-dynamixel
--gait jog --bumps 5 --from 4.5 [--push 8.0:0,-1] [--set bal_ankle_pd=0.05 ...]``
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from dataclasses import replace

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402

from robot.bus.factory import make_bus  # noqa: E402
from robot.config.gait_file import load_gait  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.config.world import Push, World  # noqa: E402
from robot.imu.tilt import tilt_from_quat  # noqa: E402
from robot.loop.telemetry import Telemetry  # noqa: E402
from robot.run.run import execute  # noqa: E402
from robot.run.spec import RunOptions  # noqa: E402
from robot.run.walk import walk_imu, walk_spec, walk_summary  # noqa: E402
from sim.mujoco.bus import MujocoBus  # noqa: E402
from sim.mujoco.foot_contact import FEET  # noqa: E402

HEADER = ("t th liftR liftL roll pitch tx ty tz rfx rfy rfz lfx lfy lfz rC lC "
          "rdx rdy ldx ldy tempo land")


def parse() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("robot")
    ap.add_argument("--gait", default="jog")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--bumps", type=float, default=0.0, help="[mm]")
    ap.add_argument("--terrain-seed", type=int, default=0)
    ap.add_argument("--slope", type=float, default=0.0, help="[deg]")
    ap.add_argument("--push", default=None, metavar="T:JX,JY", help="gait time [s], N*s")
    ap.add_argument("--seconds", type=float, default=12.0, help="gait seconds")
    ap.add_argument("--from", dest="t0", type=float, default=0.0, help="print from sim time [s]")
    ap.add_argument("--every", type=int, default=2, help="print every N control ticks")
    return ap.parse_args()


def main() -> int:
    a = parse()
    robot = load_robot(a.robot)
    params = load_gait(a.gait).for_robot(robot)
    if a.set:
        params = params.replace({k: float(v) for k, v in (s.split("=", 1) for s in a.set)},
                                where="--set")
    pushes: tuple[Push, ...] = ()
    if a.push:
        t, j = a.push.split(":")
        jx, jy = j.split(",")
        pushes = (Push(float(t), float(jx), float(jy)),)
    world = World(slope_deg=a.slope, bumps_mm=a.bumps, terrain_seed=a.terrain_seed,
                  pushes=pushes)
    bus = make_bus("sim", robot=robot, realtime=False, view=False, world=world)
    assert isinstance(bus, MujocoBus)
    imu = walk_imu(robot, bus, balance=True)
    spec = walk_spec(robot, params, bus, gait=a.gait, imu=imu,
                     options=RunOptions(seconds=a.seconds, stop_on_fall=True))
    rows: list[str] = []

    def watch(tel: Telemetry) -> None:
        if tel.tick % a.every or tel.t < a.t0:
            return
        m, d = bus.model, bus.data
        torso = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "torso")
        feet = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in FEET]
        touch: dict[int, set[str]] = {f: set() for f in feet}
        for c in d.contact[: d.ncon]:
            for f, o in ((int(c.geom1), int(c.geom2)), (int(c.geom2), int(c.geom1))):
                if f in touch and m.geom_bodyid[o] == 0:
                    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, o) or str(o)
                    touch[f].add(f"B:{name}" if name.startswith("bump") else "F")
        tilt = tilt_from_quat(tuple(d.xquat[torso]))
        roll, pitch = math.degrees(tilt.roll), math.degrees(tilt.pitch)
        e = spec.source
        tr = e.trim
        nums = (tel.t, float(e.phase.theta) % (2 * math.pi), *e.lift, roll, pitch,
                *d.xpos[torso], *d.geom_xpos[feet[0]], *d.geom_xpos[feet[1]])
        words = [",".join(sorted(touch[f])) or "-" for f in feet]
        rest = (tr.r_dx, tr.r_dy, tr.l_dx, tr.l_dy, tr.tempo, tr.land)
        rows.append(" ".join([*(f"{v:.3f}" for v in nums), *words,
                              *(f"{v:.3f}" for v in rest)]))

    spec = replace(spec, observer=watch)
    r = walk_summary(spec, execute(spec), gait=a.gait)
    print(HEADER)
    print("\n".join(rows))
    print(f"fell {r['fell']} at {r.get('fell_at_s')} s, {r['distance_m']:.2f} m, "
          f"{r['speed_m_s']:.3f} m/s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
