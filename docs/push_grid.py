"""The push grid of issue 22: 4 directions x 4 phases at one impulse, walked as the
robustness suite walks them (robot.tuning.conditions.push_grid, robot.tuning.robustness.
run_condition: `biped walk --json --stop-on-fall`, 8 s + the phase + 2 s after the push,
the preset's own gains). Prints each case (survived, fall time, speed over the run) and
the total under the walking rule: a run counts only if it did not fall and its speed over
the run is at least the robot's line (0.082 m/s Dynamixel, 0.075 m/s Feetech: about 85 %
of its unpushed walk; docs/robustness.md, "Second pass").

Run: ``MUJOCO_GL=egl nice -n 5 .venv/bin/python docs/push_grid.py --robot
biped18-dynamixel --impulse 1.0 --gait walk --jobs 1 [--set bal_step_gain=0.5 ...]
[--leg-gain position_p_gain=6000 ...] [--open-loop]``

``--leg-gain`` walks the grid with other gain registers on the leg servos (hip, knee,
ankle): the robot file is copied with a ``[joints.<leg>.gains]`` table per leg joint
(docs/servos.md: over ``[bus.gains]``, under nothing) into a temporary directory, checked
as the driver checks it (register names and ranges of the servo's gain set), and walked
from there (docs/robustness.md, issue 22, fourth pass).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from robot.commands.common import parse_sets
from robot.config.bundled import resolve_robot_path
from robot.config.gait_file import load_gait
from robot.config.joint_names import LEG_NAMES
from robot.config.params import GaitParams
from robot.config.robot_file import load_robot
from robot.config.world import PUSH_PHASES
from robot.errors import ConfigError
from robot.tuning.conditions import AFTER_PUSH_S, push_grid
from robot.tuning.robustness import Outcome, WalkJob, run_condition, worker_init

#: The walking line per robot [m/s]: a pushed run slower than this over the whole run
#: stood after the push (docs/robustness.md, issue 22, second pass).
WALK_LINE = {"biped18-dynamixel": 0.082, "biped18-feetech": 0.075}


def fail(message: str) -> int:
    print(f"push_grid: {message}", file=sys.stderr)
    return 2


def parse_pairs(option: str, items: list[str], kind: type[float] | type[int]
                ) -> dict[str, float]:
    """NAME=NUMBER items (ConfigError naming the option and the item otherwise)."""
    out: dict[str, float] = {}
    for item in items:
        name, _, value = item.partition("=")
        try:
            out[name] = kind(value)
        except ValueError:
            what = "an integer register value" if kind is int else "a number"
            raise ConfigError(f"{option} {item}: give NAME=VALUE, VALUE {what}") from None
    return out


def parse_phases(text: str) -> tuple[float, ...]:
    """Comma-separated fractions of the gait cycle, each in [0, 1) (ConfigError else)."""
    try:
        phases = tuple(float(v) for v in text.split(","))
    except ValueError:
        phases = ()
    if not phases or not all(0.0 <= p < 1.0 for p in phases):
        raise ConfigError(f"--phases {text}: give fractions of the cycle in [0, 1), "
                          "comma-separated (e.g. 0,0.125,0.25)")
    return phases


def with_leg_gains(robot: str, gains: dict[str, float], folder: Path) -> str:
    """A copy of robot file ``robot`` (bundled name or path) in ``folder`` whose leg
    joints' servos get ``gains`` (register values; a ``[joints.<name>.gains]`` table per
    leg joint), checked by loading it; its path."""
    text = resolve_robot_path(robot).read_text(encoding="utf-8")
    joints = [j.name for j in load_robot(robot).joints if j.name in LEG_NAMES]
    tables = "".join(f"\n[joints.{j}.gains]  # push_grid --leg-gain\n"
                     + "".join(f"{k} = {int(v)}\n" for k, v in gains.items())
                     for j in joints)
    out = folder / Path(resolve_robot_path(robot)).name
    out.write_text(text + tables, encoding="utf-8")
    try:
        load_robot(out)
    except ConfigError as e:      # name the option, not the temporary copy
        raise ConfigError(f"--leg-gain on {robot}: {str(e).split(': ', 1)[-1]}") from None
    return str(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", default="biped18-dynamixel")
    ap.add_argument("--impulse", type=float, default=1.0, help="[N*s]")
    ap.add_argument("--gait", default="walk")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a gait parameter on top of the preset (repeatable)")
    ap.add_argument("--leg-gain", action="append", default=[], metavar="REGISTER=VALUE",
                    help="a gain register on every leg servo (repeatable)")
    ap.add_argument("--open-loop", action="store_true", help="balance off")
    ap.add_argument("--only", default="", help="run only cases whose name contains this")
    ap.add_argument("--phases", default="", metavar="P,P,...",
                    help="push at these fractions of the cycle instead of the suite's "
                         "0, 0.25, 0.5, 0.75 (a finer map of the step)")
    a = ap.parse_args()
    worker_init()
    with tempfile.TemporaryDirectory() as folder:
        try:
            path = (with_leg_gains(a.robot, parse_pairs("--leg-gain", a.leg_gain, int),
                                   Path(folder)) if a.leg_gain else a.robot)
            robot = load_robot(path)
            params = load_gait(a.gait).for_robot(robot)
            if a.set:
                params = params.replace(parse_sets(a.set), where="--set")
            phases = parse_phases(a.phases) if a.phases else PUSH_PHASES
        except ConfigError as e:
            return fail(str(e))
        return walk_grid(a, path, params, phases)


def walk_grid(a: argparse.Namespace, path: str, params: GaitParams,
              phases: tuple[float, ...]) -> int:
    """Walk the grid for the parsed options ``a`` on robot file ``path`` at ``phases``
    (fractions of the cycle); print it."""
    robot = load_robot(path)
    line = WALK_LINE.get(robot.name, 0.0)
    conds = [c for c in push_grid(params.cycle_s, a.impulse, phases=phases) if a.only in c.name]
    jobs = []
    for c in conds:
        assert c.world is not None
        jobs.append(WalkJob(path, a.gait, params, c.world.pushes[0].at_s + AFTER_PUSH_S,
                            c, balance=not a.open_loop))
    if a.jobs > 1:
        with ProcessPoolExecutor(a.jobs, initializer=worker_init) as pool:
            outs: list[Outcome] = list(pool.map(run_condition, jobs))
    else:
        outs = [run_condition(j) for j in jobs]
    ok = 0
    for o in outs:
        speed = float(o.summary.get("speed_m_s", 0.0))
        walks = o.fell is False and speed >= line
        ok += walks
        fell = f"fell {o.fell_at_s:6.2f} s" if o.fell_at_s is not None else (
            "stopped" if o.fell else "")
        if o.error:
            fell = f"error: {o.error}"
        print(f"{o.condition.name:38s} {'WALKS' if walks else 'falls' if o.fell else 'slow':5s}"
              f" {fell:16s} {speed:6.3f} m/s")
    print(f"{a.robot} {a.gait} {a.impulse:g} N*s balance={'off' if a.open_loop else 'on'}"
          f" {' '.join(a.set + a.leg_gain)}: {ok}/{len(outs)} survived and walking on"
          f" (>= {line} m/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
