"""`biped panel`: the live puppeteering web panel (same options as `biped walk`).

Starts the gait loop (on the sim bus paced to the wall clock) and serves the page and its
JSON API. The first SIGINT/SIGTERM starts a safe stop (ramp out, rest, then torque off, or
hold with ``--hold``); a second one stops at once with torque off. Either way the bus is
closed before the process exits: 130 after SIGINT, 143 after SIGTERM, 2 for bad options.
"""

from __future__ import annotations

import argparse
import logging
import secrets
import time
from pathlib import Path
from typing import Any

from robot.commands.balance_args import feedback_factory, imu_for
from robot.commands.common import add_set_arg, bus_from, params_from, robot_from
from robot.commands.walk import add_walk_args
from robot.errors import ConfigError
from robot.panel.controller import LoopOptions, make_controller
from robot.panel.presets import PresetStore, user_presets_dir
from robot.panel.server import build_server, is_loopback, panel_url, serve_in_thread
from robot.panel.studio import Studio, user_data_dir
from robot.run.signals import SignalLatch, stop_on_signals

log = logging.getLogger(__name__)


def port_number(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        v = -1
    if not 0 <= v <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port number in [0, 65535], got {text!r}")
    return v


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("panel", help="live puppeteering web panel (same options as walk)",
                       description="Walk the robot and serve a web page with a slider for "
                                   "every gait parameter, presets, start/stop/emergency stop, "
                                   "a live stick figure and telemetry.")
    add_walk_args(p)
    add_set_arg(p)
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: "
                   "%(default)s; anything else needs a token; 0.0.0.0 for a phone)")
    p.add_argument("--http-port", type=port_number, default=8080, help="HTTP port (default: "
                   "%(default)s; 0 picks a free one)")
    p.add_argument("--token", default=None, help="access token (generated and printed when "
                   "serving beyond loopback without one)")
    p.add_argument("--presets-dir", default=None, metavar="DIR",
                   help=f"where 'save as preset' writes (default: {user_presets_dir()})")
    p.add_argument("--studio-dir", default=None, metavar="DIR",
                   help=f"where takes and keyframe sequences are kept (default: "
                        f"{user_data_dir()}: takes/, keyframes/)")
    p.add_argument("--no-start", action="store_true", help="serve without starting the gait")
    return p


class _Deferred:
    """Signal target that only records: the main thread acts on it, because a handler
    must not use the bus the main thread may be in the middle of using."""

    def __init__(self) -> None:
        self.stop = False
        self.abort = False

    def request_stop(self, reason: str = "") -> None:
        self.stop = True

    def emergency_stop(self, reason: str = "") -> None:
        self.stop = self.abort = True


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    gait, params = params_from(args, robot)
    kind = args.bus or "sim"
    if kind != "sim" and args.view:
        raise ConfigError("--view applies to --bus sim only")
    token = args.token
    if token is None and not is_loopback(args.host):
        token = secrets.token_urlsafe(18)
    presets = PresetStore(Path(args.presets_dir)) if args.presets_dir else PresetStore()
    options: dict[str, Any] = {"realtime": True, "view": args.view} if kind == "sim" else {}
    bus = bus_from(args, robot, kind=kind, **options)
    imu = imu_for(args, robot, bus)
    controller = make_controller(
        robot, bus, params,
        options=LoopOptions(rate_hz=args.rate, read_every=args.read_every, hold=args.hold,
                            feedback=feedback_factory(imu)),
        presets=presets, preset=gait.name)
    try:
        studio_dir = Path(args.studio_dir) if args.studio_dir else user_data_dir()
        studio = Studio(controller, takes_dir=studio_dir / "takes",
                        keys_dir=studio_dir / "keyframes")
        server = build_server(controller, host=args.host, port=args.http_port, token=token,
                              studio=studio)
    except OSError as e:
        raise ConfigError(f"--http-port {args.http_port}: cannot serve on {args.host}: "
                          f"{e.strerror or e}") from e
    signals, latch = _Deferred(), SignalLatch()
    with stop_on_signals(signals, latch):
        try:
            _, local = serve_in_thread(server)
            query = f"?token={token}" if token else ""
            url = panel_url(args.host, int(server.server_address[1]))
            also = f" (this machine: {local}{query})" if url != local else ""
            print(f"biped panel: {robot.name} on the {kind} bus at {args.rate:g} Hz; open "
                  f"{url}{query}{also}", flush=True)
            if token and not args.token:
                print(f"biped panel: access token {token}", flush=True)
            if not args.no_start:
                controller.start()
            while not signals.stop:
                time.sleep(0.1)
            end = "hold" if args.hold else "torque off"
            print(f"biped panel: stopping (ramp out, rest, {end}; again: torque off now)",
                  flush=True)
        finally:
            controller.shutdown(abort=lambda: signals.abort)
            server.shutdown()
            server.server_close()
            if imu is not None:
                imu.close()
    print("biped panel: stopped; torque " + ("left ON (holding)" if controller.holding and
                                             not signals.abort else "off"), flush=True)
    return latch.exit_code(None)
