"""Dual-axis servos (ROBOTIS 2XL430-W250, 2XC430-W250): two motors in one case, each with
its own control table and id, one communication module.

e-Manual 2XL430-W250, "Control Table Description": "Each motor on 2XL430 has its own
control table. However the value of Baud Rate(8) and Protocol Version(13) is always changed
at the same time because there is only one communication module in the actuator"; the two
axes must have different ids ("if you try to set the same ID, Data Limit Error(0x06)
occurs and the setting is not applied"). The axes of a case share ``ServoSpec.case``;
:func:`link_cases` makes them partners (``servo_write`` refuses the shared id and copies
the shared settings, ``servo_write.CASE_SHARED``), and a case is plugged in as one part (:func:`case_mates`).
"""

from __future__ import annotations

from collections.abc import Sequence

from sim.emulator.servo import EmulatedServo


def link_cases(servos: Sequence[object]) -> None:
    """Make the two axes of every case each other's partner (LX servos have no cases)."""
    by_case: dict[int, list[EmulatedServo]] = {}
    for s in servos:
        if isinstance(s, EmulatedServo) and s.spec.case:
            by_case.setdefault(s.spec.case, []).append(s)
    for axes in by_case.values():
        if len(axes) == 2:
            axes[0].partner, axes[1].partner = axes[1], axes[0]


def case_mates(servos: Sequence[object], index: int) -> list[int]:
    """Indices of the servos in the same case as servo ``index`` (itself included)."""
    def case(s: object) -> int:
        return s.spec.case if isinstance(s, EmulatedServo) else 0
    if not case(servos[index]):
        return [index]
    return [i for i, s in enumerate(servos) if case(s) == case(servos[index])]
