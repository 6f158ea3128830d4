"""`biped sim-gap TAKE`: how far the simulation is from the servos a take was recorded on.

A take recorded on a servo bus (``biped walk --bus ... --record NAME.take.jsonl``, or the
panel's takes on a bus) carries the commands and, every read-back tick, the positions
read back. The commands are replayed in the simulation (``sim.mujoco.take_replay``: the
whole robot, ``--world robot``, or each servo alone on a bench as ``biped emulate`` serves
them, ``--world bench`` with ``--load``); per joint, over the read-back ticks, it prints
the tracking error of the real servos against the commands, of the simulated ones against
the commands, and real against simulated: RMS and largest, in degrees (``--json``: in
radians), and plots the three over time (``--plot``). docs/servos.md says how to read it.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robot.commands.common import checked, input_file, plot_output
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.loop.mcap_recorder import is_mcap
from robot.motion.takes import Take, read_take
from robot.previs.figure_file import save_figure
from robot.previs.mcap_read import mcap_take
from robot.servo.bench_load import BenchLoad, parse_load

log = logging.getLogger(__name__)

Floats = npt.NDArray[np.float64]
PAIRS = ("real_cmd", "sim_cmd", "real_sim")


@dataclass(frozen=True)
class JointGap:
    """One joint's errors [rad] over the read-back ticks: RMS and largest |difference|
    of real - command, sim - command, real - sim."""

    joint: str
    rms_real_cmd: float
    max_real_cmd: float
    rms_sim_cmd: float
    max_sim_cmd: float
    rms_real_sim: float
    max_real_sim: float


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = subparsers.add_parser("sim-gap", help="compare a take recorded on servos with the "
                              "simulation of the same commands", description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("take", metavar="TAKE", help="a take recorded on a servo bus (.take.jsonl; or a .mcap)")
    p.add_argument("--robot", default=None, metavar="NAME|PATH",
                   help="the robot file to simulate (default: the one the take names)")
    p.add_argument("--world", choices=("robot", "bench"), default="robot",
                   help="robot: the whole robot on the floor (default); bench: each servo "
                        "alone, as biped emulate serves them")
    p.add_argument("--load", action="append", default=[], metavar="JOINT=MASS@LENGTH",
                   help="bench: a weight [kg] on an arm [m] on that joint's servo (repeatable)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", default=None, metavar="PNG",
                   help="plot the three errors over time per joint")
    return p


def loads_from(texts: list[str]) -> dict[str, BenchLoad]:
    """``JOINT=MASS@LENGTH`` texts → joint → load."""
    out: dict[str, BenchLoad] = {}
    for text in texts:
        name, sep, rest = text.partition("=")
        if not sep or not name:
            raise ConfigError(f"--load: expected JOINT=MASS@LENGTH (e.g. r_knee=0.5@0.1), "
                              f"got {text!r}")
        out[name] = parse_load(rest, where=f"--load {text}")
    return out


def robot_for(take: Take, text: str | None) -> RobotConfig:
    """``--robot``, else the robot file the take names (if it is there), else its name."""
    if text is not None:
        return load_robot(text)
    named = Path(take.header.robot_file)
    return load_robot(named if take.header.robot_file and named.is_file()
                      else take.header.robot)


def gaps(robot: RobotConfig, take: Take, sim: Floats) -> list[JointGap]:
    """Per joint, the errors over the ticks where both the read-back and the sim exist."""
    assert take.present is not None
    out = []
    for j, name in enumerate(robot.joint_names):
        real, cmd, s = take.present[:, j], take.q[:, j], sim[:, j]
        ok = np.isfinite(real) & np.isfinite(s)
        diffs = (real[ok] - cmd[ok], s[ok] - cmd[ok], real[ok] - s[ok])
        stats: list[float] = []
        for d in diffs:
            stats += [float(np.sqrt(np.mean(d ** 2))), float(np.max(np.abs(d)))]
        out.append(JointGap(name, *stats))
    return out


def table(rows: list[JointGap]) -> str:
    head = (f"{'joint':<18} {'real-cmd rms/max':>17} {'sim-cmd rms/max':>17} "
            f"{'real-sim rms/max':>17}   [deg]")
    lines = [head]
    for r in rows:
        cells = [f"{math.degrees(a):7.2f} /{math.degrees(b):7.2f}" for a, b in (
            (r.rms_real_cmd, r.max_real_cmd), (r.rms_sim_cmd, r.max_sim_cmd),
            (r.rms_real_sim, r.max_real_sim))]
        lines.append(f"{r.joint:<18} " + " ".join(f"{c:>17}" for c in cells))
    return "\n".join(lines)


def plot(robot: RobotConfig, take: Take, sim: Floats, path: str) -> None:
    """One panel per joint: real - cmd, sim - cmd, real - sim [deg] over the take's time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    assert take.present is not None
    n = len(robot.joint_names)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.5 * cols, 2.4 * rows), squeeze=False,
                             sharex=True)
    ok = np.isfinite(take.present).all(axis=1) & np.isfinite(sim).all(axis=1)
    t = take.t[ok]
    for j, (ax, name) in enumerate(zip(axes.flat, robot.joint_names, strict=False)):
        real, cmd, s = take.present[ok, j], take.q[ok, j], sim[ok, j]
        for y, label in ((real - cmd, "real - cmd"), (s - cmd, "sim - cmd"),
                         (real - s, "real - sim")):
            ax.plot(t, np.degrees(y), lw=1, label=label)
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    fig.suptitle(f"sim-gap: {Path(take.source).name} [deg]")
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from sim.mujoco.take_replay import replay

    plot_path = None if args.plot is None else checked("--plot", plot_output, args.plot)
    path = checked("TAKE", input_file, args.take)
    take = mcap_take(path) if is_mcap(path) else read_take(path)
    robot = robot_for(take, args.robot)
    recorded_on = take.header.robot
    if recorded_on and recorded_on != robot.name:
        log.warning("%s was recorded on robot %r; simulating %r (--robot): the gap "
                    "includes how the two robots differ (without --robot: the one the "
                    "take names)", take.source, recorded_on, robot.name)
    loads = loads_from(args.load)
    if loads and args.world != "bench":
        raise ConfigError("--load: only with --world bench (the robot world has its body)")
    sim = replay(robot, take, world=args.world, loads=loads)
    rows = gaps(robot, take, sim)
    assert take.present is not None           # replay refused a take without read-backs
    reads = int((np.isfinite(take.present).all(axis=1) & np.isfinite(sim).all(axis=1)).sum())
    if plot_path is not None:
        plot(robot, take, sim, plot_path)
    if args.json:
        print(json.dumps({"take": take.source, "robot": robot.name,
                          "recorded_on": recorded_on, "world": args.world,
                          "read_backs": reads,
                          "joints": [asdict(r) for r in rows]}))
    else:
        other = f" (recorded on {recorded_on})" if recorded_on != robot.name else ""
        print(f"{take.source}: {robot.name}{other}, {args.world} world, {reads} read-back "
              "ticks")
        print(table(rows))
    return 0
