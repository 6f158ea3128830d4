"""One control-table entry (``Register``): the type every table in robot/bus/tables*.py is
made of."""

from __future__ import annotations

from typing import NamedTuple


class Register(NamedTuple):
    """One control-table entry.

    address: byte address in the servo's control table
    size: width [bytes]
    """

    address: int
    size: int
