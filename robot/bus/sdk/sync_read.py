"""Sync read of one register block that never hands out stale data.

Replies are collected here with the packet handler's ``readRx`` rather than by
``GroupSyncRead.rxPacket`` so that (a) only data received in *this* read is returned (the
Feetech SDK's GroupSyncRead reports old data as available after a failed read) and (b) each
servo's status byte is kept (Dynamixel's alert bit, Feetech's error bits). A servo that
does not answer silences the ones after it on a real chain, so a retry re-reads only the
ids still missing.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

#: Reply per servo: (block bytes, status-packet error byte).
Reply = tuple[bytes, int]


class BlockSyncRead:
    """``start``/``length``: the register block [address, bytes]; ``sdk``: the vendor module.

    Call :meth:`bind` after (re)opening the port, then :meth:`exchange` once per attempt.
    """

    def __init__(self, sdk: ModuleType, start: int, length: int) -> None:
        self.sdk = sdk
        self.start = start
        self.length = length
        self.failed: int | None = None
        self._port: Any = None
        self._ph: Any = None
        self._groups: dict[tuple[int, ...], Any] = {}

    def bind(self, port: Any, packet_handler: Any) -> None:
        self._port, self._ph = port, packet_handler
        self._groups.clear()

    def _group(self, ids: tuple[int, ...]) -> Any:
        """A GroupSyncRead for exactly ``ids``, reused across calls (never re-addParam)."""
        group = self._groups.get(ids)
        if group is None:
            if len(self._groups) >= 8:
                self._groups.clear()
            group = self.sdk.GroupSyncRead(self._port, self._ph, self.start, self.length)
            for sid in ids:
                group.addParam(sid)
            self._groups[ids] = group
        return group

    def exchange(self, ids: tuple[int, ...], got: dict[int, Reply]) -> tuple[None, int, int]:
        """One attempt for the ``ids`` not yet in ``got`` (filled in place).

        Returns (None, SDK comm result, 0) for ``SdkBus._transact``; on failure
        ``self.failed`` is the first id without a valid reply (None if the send failed).
        """
        self.failed = None
        todo = tuple(i for i in ids if i not in got)
        result = self._group(todo).txPacket()
        if result != self.sdk.COMM_SUCCESS:
            return None, result, 0
        for sid in todo:
            data, result, error = self._ph.readRx(self._port, sid, self.length)
            if result == self.sdk.COMM_SUCCESS and len(data) < self.length:
                result = self.sdk.COMM_RX_CORRUPT
            if result != self.sdk.COMM_SUCCESS:
                self.failed = sid
                return None, result, 0
            got[sid] = (bytes(data), error)
        return None, result, 0
