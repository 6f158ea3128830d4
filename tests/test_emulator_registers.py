"""Every register of the manuals' tables exists on the emulated servo, through the SDKs.

The tables are written out here from the manuals (address, size, access), independent of
``sim/emulator/control_tables.py``: ROBOTIS e-Manual XL430-W250 and AX-12A control tables,
Feetech STS memory table (STS3215). Each register is read; each writable one takes back the
value it holds; each read-only one refuses a write the way the servo does: Protocol 2.0
answers Access Error 7 (e-Manual, Protocol 2.0 status packet: "attempt to write a value in
an address that is read only"), Protocol 1.0 sets the Range Error bit 3 (e-Manual, Protocol
1.0: "the instruction sent is out of the defined range"; 1.0 has no access code), and the
STS answers without an error and ignores it (its status byte carries only the servo state).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from sdk_link import served
from sdk_timeouts import allow_slow_replies

BAUD = 1_000_000
XL430 = [  # (address, size, access)
    (0, 2, "R"), (2, 4, "R"), (6, 1, "R"), (7, 1, "RW"), (8, 1, "RW"), (9, 1, "RW"),
    (10, 1, "RW"), (11, 1, "RW"), (12, 1, "RW"), (13, 1, "RW"), (20, 4, "RW"), (24, 4, "RW"),
    (31, 1, "RW"), (32, 2, "RW"), (34, 2, "RW"), (36, 2, "RW"), (44, 4, "RW"), (48, 4, "RW"),
    (52, 4, "RW"), (60, 1, "RW"), (63, 1, "RW"), (64, 1, "RW"), (65, 1, "RW"), (68, 1, "RW"),
    (69, 1, "R"), (70, 1, "R"), (76, 2, "RW"), (78, 2, "RW"), (80, 2, "RW"), (82, 2, "RW"),
    (84, 2, "RW"), (88, 2, "RW"), (90, 2, "RW"), (98, 1, "RW"), (100, 2, "RW"),
    (104, 4, "RW"), (108, 4, "RW"), (112, 4, "RW"), (116, 4, "RW"), (120, 2, "R"),
    (122, 1, "R"), (123, 1, "R"), (124, 2, "R"), (126, 2, "R"), (128, 4, "R"), (132, 4, "R"),
    (136, 4, "R"), (140, 4, "R"), (144, 2, "R"), (146, 1, "R"), (147, 1, "R"),
    (168, 2, "RW"), (224, 1, "RW"), (578, 2, "RW"), (634, 1, "RW"),
]
AX12A = [
    (0, 2, "R"), (2, 1, "R"), (3, 1, "RW"), (4, 1, "RW"), (5, 1, "RW"), (6, 2, "RW"),
    (8, 2, "RW"), (11, 1, "RW"), (12, 1, "RW"), (13, 1, "RW"), (14, 2, "RW"), (16, 1, "RW"),
    (17, 1, "RW"), (18, 1, "RW"), (24, 1, "RW"), (25, 1, "RW"), (26, 1, "RW"), (27, 1, "RW"),
    (28, 1, "RW"), (29, 1, "RW"), (30, 2, "RW"), (32, 2, "RW"), (34, 2, "RW"), (36, 2, "R"),
    (38, 2, "R"), (40, 2, "R"), (42, 1, "R"), (43, 1, "R"), (44, 1, "R"), (46, 1, "R"),
    (47, 1, "RW"), (48, 2, "RW"),
]
STS3215 = [
    (0, 1, "R"), (1, 1, "R"), (3, 2, "R"), (5, 1, "RW"), (6, 1, "RW"), (7, 1, "RW"),
    (8, 1, "RW"), (9, 2, "RW"), (11, 2, "RW"), (13, 1, "RW"), (14, 1, "RW"), (15, 1, "RW"),
    (16, 2, "RW"), (18, 1, "RW"), (19, 1, "RW"), (20, 1, "RW"), (21, 1, "RW"), (22, 1, "RW"),
    (23, 1, "RW"), (24, 1, "RW"), (26, 1, "RW"), (27, 1, "RW"), (28, 2, "RW"), (30, 1, "RW"),
    (31, 2, "RW"), (33, 1, "RW"), (34, 1, "RW"), (35, 1, "RW"), (36, 1, "RW"), (37, 1, "RW"),
    (38, 1, "RW"), (39, 1, "RW"), (40, 1, "RW"), (41, 1, "RW"), (42, 2, "RW"), (44, 2, "RW"),
    (46, 2, "RW"), (48, 2, "RW"), (55, 1, "RW"), (56, 2, "R"), (58, 2, "R"), (60, 2, "R"),
    (62, 1, "R"), (63, 1, "R"), (64, 1, "R"), (65, 1, "R"), (66, 1, "R"), (69, 2, "R"),
    (80, 1, "RW"), (81, 1, "RW"), (82, 1, "RW"), (83, 1, "RW"), (84, 1, "RW"), (85, 1, "RW"),
    (86, 1, "RW"),
]
#: What a write to a read-only register answers: (comm result, error byte).
READ_ONLY_ANSWER = {"dynamixel": (0, 7), "dynamixel1": (0, 1 << 3), "feetech": (0, 0)}
TABLES = {"dynamixel": XL430, "dynamixel1": AX12A, "feetech": STS3215}


@pytest.fixture(autouse=True)
def patient_sdks(monkeypatch: pytest.MonkeyPatch) -> None:
    allow_slow_replies(monkeypatch)


@pytest.fixture(params=sorted(TABLES))
def link(request: pytest.FixtureRequest) -> Iterator[tuple[str, Any, Any]]:
    for _, port, ph in served(str(request.param), [1], BAUD):
        yield str(request.param), port, ph


def _read(ph: Any, port: Any, address: int, size: int) -> tuple[int, int, int]:
    fn = {1: ph.read1ByteTxRx, 2: ph.read2ByteTxRx, 4: ph.read4ByteTxRx}[size]
    return tuple(fn(port, 1, address))  # type: ignore[return-value]


def _write(ph: Any, port: Any, address: int, size: int, value: int) -> tuple[int, int]:
    fn = {1: ph.write1ByteTxRx, 2: ph.write2ByteTxRx, 4: ph.write4ByteTxRx}[size]
    return tuple(fn(port, 1, address, value))  # type: ignore[return-value]


def test_every_register_reads_and_takes_writes_as_the_manual_says(
        link: tuple[str, Any, Any]) -> None:
    protocol, port, ph = link
    for address, size, access in TABLES[protocol]:
        value, comm, error = _read(ph, port, address, size)
        assert (comm, error) == (0, 0), (protocol, address)
        answer = _write(ph, port, address, size, value if access == "RW" else value ^ 1)
        expected = (0, 0) if access == "RW" else READ_ONLY_ANSWER[protocol]
        assert answer == expected, (protocol, address, access)
        if access == "R" and address not in (120,):     # Realtime Tick counts by itself
            assert _read(ph, port, address, size)[0] == value, (protocol, address)
