"""`biped panel`: the live puppeteering web panel (same options as `biped walk`).

Starts the gait loop (on the sim bus paced to the wall clock) and serves the page and its
JSON API until Ctrl-C, then stops safely (ramp out, rest, torque off).
"""

from __future__ import annotations

import argparse
import logging
import secrets
import signal
import threading
from pathlib import Path
from typing import Any

from robot.bus.factory import make_bus
from robot.commands.common import add_set_arg, params_from, robot_from
from robot.commands.walk import add_walk_args
from robot.config import GAITS_DIR
from robot.errors import ConfigError
from robot.panel.controller import LoopOptions, make_controller
from robot.panel.presets import PresetStore
from robot.panel.server import build_server, is_loopback, serve_in_thread

log = logging.getLogger(__name__)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("panel", help="live puppeteering web panel (same options as walk)",
                       description="Walk the robot and serve a web page with a slider for "
                                   "every gait parameter, presets, start/stop/emergency stop, "
                                   "a live stick figure and telemetry.")
    add_walk_args(p)
    add_set_arg(p)
    p.add_argument("--host", default="127.0.0.1", help="address to serve on (default: "
                   "%(default)s; anything else needs a token)")
    p.add_argument("--http-port", type=int, default=8080, help="HTTP port (default: "
                   "%(default)s; 0 picks a free one)")
    p.add_argument("--token", default=None, help="access token (generated and printed when "
                   "serving beyond loopback without one)")
    p.add_argument("--presets-dir", default=str(GAITS_DIR), metavar="DIR",
                   help="where 'save as preset' writes (default: %(default)s)")
    p.add_argument("--no-start", action="store_true", help="serve without starting the gait")
    return p


def run(args: argparse.Namespace) -> int:
    robot = robot_from(args)
    gait, params = params_from(args)
    kind = args.bus or "sim"
    if kind != "sim" and args.view:
        raise ConfigError("--view applies to --bus sim only")
    token = args.token
    if token is None and not is_loopback(args.host):
        token = secrets.token_urlsafe(18)
    options: dict[str, Any] = {"realtime": True, "view": args.view} if kind == "sim" else {}
    bus = make_bus(kind, robot=robot, port=args.port, baud=args.baud, **options)
    controller = make_controller(
        robot, bus, params,
        options=LoopOptions(rate_hz=args.rate, read_every=args.read_every, hold=args.hold),
        presets=PresetStore(Path(args.presets_dir)), preset=gait.name)
    try:
        server = build_server(controller, host=args.host, port=args.http_port, token=token)
    except OSError as e:
        raise ConfigError(f"--http-port {args.http_port}: cannot serve on {args.host}: "
                          f"{e.strerror or e}") from e
    _, base = serve_in_thread(server)
    if not is_loopback(args.host):
        base = base.replace("127.0.0.1", args.host).replace("[::1]", f"[{args.host}]")
    url = base + (f"?token={token}" if token else "")
    print(f"biped panel: {robot.name} on the {kind} bus at {args.rate:g} Hz; open {url}",
          flush=True)
    if token and not args.token:
        print(f"biped panel: access token {token}", flush=True)

    def on_term(_signum: int, _frame: Any) -> None:
        raise KeyboardInterrupt
    old_term = signal.signal(signal.SIGTERM, on_term)
    try:
        if not args.no_start:
            controller.start()
        threading.Event().wait()
    except KeyboardInterrupt:
        print("biped panel: stopping (ramp out, rest, torque off)", flush=True)
    finally:
        signal.signal(signal.SIGTERM, old_term)
        server.shutdown()
        server.server_close()
        controller.shutdown()
    return 0
