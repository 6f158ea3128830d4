"""`biped panel`: the live puppeteering web panel (same options as `biped walk`).

Starts the control loop in a process of its own (on the sim bus paced to the wall clock,
or the servos) and serves the page and its JSON API from this one. The first
SIGINT/SIGTERM starts a safe stop (ramp out, rest, then torque off, or hold with
``--hold``); a second one stops at once with torque off; any later one is ignored. Either
way the bus is closed before the process exits: 130 after SIGINT, 143 after SIGTERM
(never killed by the signal), 2 for bad options, 1 when torque could not be confirmed
off at the end (the last line says which servos) or when the control loop's process died
(SIGKILL, the OOM killer): then this process opens the port and turns torque off itself
(robot.panel.loop_lost).
"""

from __future__ import annotations

import argparse
import logging
import os
import secrets
import time
from pathlib import Path
from typing import Any

from robot.commands.common import add_set_arg, bus_from, params_from, robot_from
from robot.commands.show_args import add_show_args, show_options
from robot.commands.walk import add_walk_args
from robot.errors import ConfigError
from robot.panel.controller import BusSpec, LoopOptions, PanelController
from robot.panel.presets import PresetStore, user_presets_dir
from robot.panel.server import build_server, is_loopback, panel_url, serve_in_thread
from robot.panel.show_control import PanelShowControl
from robot.panel.studio import Studio, user_data_dir
from robot.run.signals import stop_on_signals

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
    p.add_argument("--mcap", action="store_true", help="each recorded take also as NAME.mcap "
                   "beside it (opens in Foxglove; docs/show-control.md)")
    add_show_args(p)
    return p


class _Deferred:
    """Signal target that only records: the main thread acts on it (a handler must not
    wait on the loop process the main thread may be waiting on)."""

    def __init__(self) -> None:
        self.stop = False
        self.abort = False

    def request_stop(self, reason: str = "") -> None:
        self.stop = True

    def emergency_stop(self, reason: str = "") -> None:
        self.stop = self.abort = True


#: How much lower this process's CPU priority is than the loop process's (nice units).
WEB_NICE = 5


def _give_way() -> None:
    """Lower this process's CPU priority below the loop process's (started already, it
    keeps its own): on a busy machine the scheduler prefers the loop to the web side."""
    try:
        os.nice(WEB_NICE)
    except OSError as e:
        log.debug("could not lower the web side's priority: %s", e)


def _farewell(report: dict[str, Any], *, aborted: bool) -> tuple[str, bool]:
    """The last line, from what the loop told the wire; and whether torque is safe."""
    failed = list(report.get("failed", []))
    torque = report.get("torque", {})
    on = sorted(i for i, v in torque.items() if v)
    if not report:
        return "torque untouched (the bus was never opened)", True
    if report.get("sim"):
        return "the simulation ended with the control loop process; nothing to turn off", False
    if report.get("holding") and not aborted and not failed:
        return "torque left ON (holding)", True
    if failed or on:
        unsure = on or sorted(torque) or ["all"]
        why = failed[0] if failed else "the bus did not confirm it"
        return (f"torque NOT confirmed off on servos {', '.join(map(str, unsure))}: {why}; "
                "a servo with a bus watchdog stops where it is, check the others", False)
    return "torque off", True


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
    bus_from(args, robot, kind=kind, **options)     # --bus / --baud refused here, one line
    controller = PanelController(
        robot, BusSpec(kind, port=args.port, baud=args.baud, options=options), params,
        options=LoopOptions(rate_hz=args.rate, read_every=args.read_every, hold=args.hold,
                            balance=not args.no_balance, imu_noise=args.imu_noise,
                            mcap=args.mcap),
        presets=presets, preset=gait.name)
    studio_dir = Path(args.studio_dir) if args.studio_dir else user_data_dir()
    studio = Studio(controller, takes_dir=studio_dir / "takes",
                    keys_dir=studio_dir / "keyframes")
    shows = show_options(args, studio_dir=studio_dir)    # files checked: nothing moved yet
    show = PanelShowControl(controller, shows) if shows.on else None
    signals = _Deferred()
    server = None
    report: dict[str, Any] = {}
    with stop_on_signals(signals) as latch:   # to the end: a signal is never an exception
        try:
            controller.open()             # the loop process, the bus open: or one line
            _give_way()
            try:
                server = build_server(controller, host=args.host, port=args.http_port,
                                      token=token, studio=studio,
                                      more_routes=show.routes() if show else None)
            except OSError as e:
                raise ConfigError(f"--http-port {args.http_port}: cannot serve on "
                                  f"{args.host}: {e.strerror or e}") from e
            _, local = serve_in_thread(server)
            query = f"?token={token}" if token else ""
            url = panel_url(args.host, int(server.server_address[1]))
            also = f" (this machine: {local}{query})" if url != local else ""
            print(f"biped panel: {robot.name} on the {kind} bus at {args.rate:g} Hz; open "
                  f"{url}{query}{also}", flush=True)
            if token and not args.token:
                print(f"biped panel: access token {token}", flush=True)
            if show is not None:
                show.open(server.routes)
                if show.osc is not None:
                    print(f"biped panel: OSC on {show.osc.host}:{show.osc.port}", flush=True)
            if not args.no_start and not signals.stop:
                controller.start()
            while not signals.stop and controller.loop.gone is None:
                time.sleep(0.1)
            if controller.loop.gone is not None:
                log.error("%s", controller.loop.gone)
                print("biped panel: stopping (the control loop is gone: torque off from "
                      "this process)" if kind != "sim" else "biped panel: stopping", flush=True)
            else:
                end = "hold" if args.hold else "torque off"
                print(f"biped panel: stopping (ramp out, rest, {end}; again: torque off now)",
                      flush=True)
        finally:
            report = controller.shutdown(abort=lambda: signals.abort)  # first: a second
            if server is not None:                                    # signal acts at once
                server.shutdown()
                server.server_close()
            if show is not None:
                show.close()
        line, safe = _farewell(report, aborted=signals.abort)
        if report.get("lost") and safe:
            line += " (by this process: the control loop process had ended)"
        print(f"biped panel: stopped; {line}", flush=True)
    return latch.exit_code(None) if safe and not report.get("lost") else 1
