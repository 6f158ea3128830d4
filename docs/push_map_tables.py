"""Markdown tables of a push map (`biped robustness --push-map --json`, the files in
docs/push_map/): the capture limits per direction (median over the phases, and the
range), and the survived push as a share of the 1-step limit per direction and phase.

Run: ``python docs/push_map_tables.py docs/push_map/biped18-dynamixel-before.json``
(``--png``: also draw each file's polar plots again, beside it as .png, as
`biped robustness --push-map --out` draws them).
"""

from __future__ import annotations

import json
import statistics
import sys
from typing import Any


def limits_table(cells: list[dict[str, Any]]) -> str:
    dirs = sorted({c["direction_deg"] for c in cells})
    out = ["| steps | " + " | ".join(f"{d:g} deg" for d in dirs) + " |",
           "|---|" + "---|" * len(dirs)]
    for n in ("0", "1", "2"):
        row = []
        for d in dirs:
            v = [c["limit_n_s"][n] for c in cells if c["direction_deg"] == d]
            row.append(f"{statistics.median(v):.2f} ({min(v):.2f}-{max(v):.2f})")
        out.append(f"| {n} | " + " | ".join(row) + " |")
    return "\n".join(out)


def share_table(cells: list[dict[str, Any]]) -> str:
    dirs = sorted({c["direction_deg"] for c in cells})
    phases = sorted({c["phase"] for c in cells})
    at = {(c["phase"], c["direction_deg"]): c for c in cells}
    out = ["| phase | " + " | ".join(f"{d:g}" for d in dirs) + " |",
           "|---|" + "---|" * len(dirs)]
    for ph in phases:
        row = []
        for d in dirs:
            c = at[(ph, d)]
            share = c["share_of_1_step"]
            row.append(f"{c['survived_n_s']:.2f} ({100 * share:.0f} %)" if share is not None
                       else f"{c['survived_n_s']:.2f}")
        out.append(f"| {ph:.4f} | " + " | ".join(row) + " |")
    return "\n".join(out)


def replot(path: str, m: dict[str, Any]) -> None:
    from robot.commands.push_map import plot_map
    from robot.tuning.push_map import Cell
    cells = [Cell(c["direction_deg"], c["phase"], c["at_s"], c["balance"], c["survived_n_s"],
                  {int(k): v for k, v in c["limit_n_s"].items()}) for c in m["cells"]]
    plot_map(cells, path.removesuffix(".json") + ".png", title=f"{m['robot']}, gait {m['gait']}")


def main() -> int:
    png = "--png" in sys.argv
    for path in [a for a in sys.argv[1:] if a != "--png"]:
        m = json.load(open(path))
        if png:
            replot(path, m)
        for balance in (True, False):
            cells = [c for c in m["cells"] if c["balance"] is balance]
            if not cells:
                continue
            g = m["goal"]["balance" if balance else "open_loop"]
            print(f"### {m['robot']}, {'balance' if balance else 'open loop'} ({path})\n")
            print(f"least share {100 * g['least']:.0f} %, median {100 * g['median']:.0f} %\n")
            print("Capture limits [N*s], median (range) over the phases:\n")
            print(limits_table(cells) + "\n")
            print("Survived [N*s] (share of the 1-step limit):\n")
            print(share_table(cells) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
