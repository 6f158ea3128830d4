"""Dynamixel X indirect addressing (e-Manual XL430-W250, "Indirect Address / Indirect Data").

Each Indirect Data byte stands for the byte its Indirect Address register points at: a read
of it reads that byte, a write to it writes there. ``IndirectMap`` maps an Indirect Data
address to the name of its Indirect Address register; tables without indirect addressing
have an empty map.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from sim.emulator.control_tables import Entry

IndirectMap = Mapping[int, str]


def indirect_map(table: Mapping[str, Entry]) -> dict[int, str]:
    """Indirect Data address -> name of the Indirect Address register pointing it."""
    return {e.address: name.replace("data", "address")
            for name, e in table.items() if name.startswith("indirect_data")}


def target(indirect: IndirectMap, get: Callable[[str], int], address: int) -> int | None:
    """Where the byte at ``address`` really is (None: not an Indirect Data byte)."""
    name = indirect.get(address)
    return None if name is None else get(name)


def runs(indirect: IndirectMap, get: Callable[[str], int], address: int,
         data: bytes) -> list[tuple[int, bytes]]:
    """A write of ``data`` at ``address`` as (address, bytes) runs after translation."""
    out: list[tuple[int, bytearray]] = []
    for i, b in enumerate(data):
        moved = target(indirect, get, address + i)
        a = address + i if moved is None else moved
        if out and out[-1][0] + len(out[-1][1]) == a:
            out[-1][1].append(b)
        else:
            out.append((a, bytearray([b])))
    return [(a, bytes(d)) for a, d in out] or [(address, b"")]
