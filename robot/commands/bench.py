"""`biped bench`: kinematic core, buses over the emulator, and the control loop."""

from __future__ import annotations

import argparse
import importlib
import json
from typing import Any

from robot.commands.common import bounded_float

SECTIONS: dict[str, str] = {
    "core": "robot.bench.core:run_core_bench",
    "bus": "robot.bench.core:run_bus_section",
    "wire": "robot.bench.wire:run_wire_bench",
    "loop": "robot.bench.loop:run_loop_bench",
    "sim": "robot.bench.sim:run_sim_bench",
    "panel": "robot.bench.panel:run_panel_bench",
    "panel-flood": "robot.bench.panel_flood:run_flood_bench",
    "panel-soak": "robot.bench.panel_soak:run_soak_bench",
    "osc": "robot.bench.osc:run_osc_bench",
}
#: Run only when named with --only (an hour by default).
ON_REQUEST = ("panel-soak",)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("bench", help="run the benchmarks and report percentiles and ratios")
    p.add_argument("--only", choices=sorted(SECTIONS), action="append",
                   help="run only these sections (repeatable)")
    p.add_argument("--quick", action="store_true", help="fewer iterations (a smoke run)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--minutes", type=bounded_float(0.5, 1440.0, "min", what="a duration"),
                   default=None,
                   help="panel-soak: how long the session lasts (default 60; 3 with --quick)")
    return p


def _load(ref: str) -> Any:
    module, func = ref.split(":")
    return getattr(importlib.import_module(module), func)


def _fmt(d: Any, indent: str = "  ") -> list[str]:
    lines = []
    for k, v in d.items():
        if isinstance(v, dict):
            lines.append(f"{indent}{k}:")
            lines += _fmt(v, indent + "  ")
        elif isinstance(v, float):
            lines.append(f"{indent}{k}: {v:,.3f}")
        else:
            lines.append(f"{indent}{k}: {v}")
    return lines


def run(args: argparse.Namespace) -> int:
    results: dict[str, Any] = {}
    for name in args.only or [n for n in SECTIONS if n not in ON_REQUEST]:
        extra = {"minutes": args.minutes} if name == "panel-soak" else {}
        results[name] = _load(SECTIONS[name])(quick=args.quick, **extra)
        if not args.json:
            print(f"{name}:")
            print("\n".join(_fmt(results[name])))
    if args.json:
        print(json.dumps(results, indent=2))
    return 0
