"""`biped plot`: a PNG of a `biped walk --record` file (.csv or .jsonl) or a `biped curves`
CSV (told apart by their columns)."""

from __future__ import annotations

import argparse

from robot.commands.common import checked, input_file, one_line_errors, plot_output, writing


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:  # type: ignore[type-arg]
    p = sub.add_parser("plot", help="plot a run record or a curves file to a PNG",
                       description="Commanded vs present joint positions, loop timing, "
                                   "temperatures and loads of a recorded walk; or the "
                                   "channels and joint angles of a curves CSV.")
    p.add_argument("file", metavar="FILE", help="run record (.csv/.jsonl/.mcap) or curves CSV")
    p.add_argument("--out", required=True, metavar="FILE.png", help="PNG to write")
    return one_line_errors(p)


def run(args: argparse.Namespace) -> int:
    from robot.previs.plots import plot_file

    # Checked here rather than as argparse types so that main() returns 2 like for a bad file.
    checked("FILE", input_file, args.file)
    checked("--out", plot_output, args.out)
    with writing("--out", args.out):
        kind = plot_file(args.file, args.out)
    print(f"wrote {args.out} ({kind} plot of {args.file})")
    return 0
