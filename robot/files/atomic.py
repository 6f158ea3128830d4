"""Output files written whole or not at all: the one way every command writes a file.

A file is written under a temporary name in its own folder (``.NAME.XXXXXXXX.SUFFIX``: the
same file system, hidden, and not ending like the file it becomes) and renamed onto its
name once whole (``os.replace``): a reader sees the old file or the new one, never part of
one; a failure or a refused start leaves the old file as it was.

- ``write_text(path, text)`` / ``write_bytes(path, data)``: a file made in one piece.
- ``replacing(path)``: the name a library should write (matplotlib, pygltflib, imageio,
  ffmpeg, wave), renamed when the block ends, removed if it raises.
- ``OutputFile(path)``: a file written as a run goes (the CSV/JSONL recorder, the take
  writer), in whole records: ``commit()`` renames it (after a failed write, e.g. a full
  disk, with the records before the failed one), ``discard()`` keeps the old file.

A symbolic link is followed (its target is replaced, the link stays). A path that exists
and is not a regular file (a device such as /dev/full or /dev/null, a FIFO) cannot be
renamed onto: it is written in place, and its errors (ENOSPC) are raised as a file's are.
The new file has the permission bits of the file it replaces, else ``NEW_MODE``; it is
flushed to the disk (fsync) before the rename, so a power cut leaves one file or the other.
"""

from __future__ import annotations

import errno
import io
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

#: Permission bits of a new file: read for everyone, write for the owner.
NEW_MODE = 0o644


def _target(path: str | Path) -> tuple[Path, bool]:
    """The file to replace (links followed), and whether it is written in place (it
    exists and is not a regular file)."""
    target = Path(os.path.realpath(path))
    try:
        mode = target.stat().st_mode
    except FileNotFoundError:
        return target, False
    return target, not stat.S_ISREG(mode)


def _temporary(path: str | Path, target: Path, *, beside_name: bool = False
               ) -> tuple[int, Path]:
    """A new temporary file in ``target``'s folder (``beside_name``: in the folder of the
    name given), ending in the suffix of the name given (libraries read the format
    from it)."""
    given = Path(path)
    folder = given.absolute().parent if beside_name else target.parent
    fd, name = tempfile.mkstemp(prefix=f".{given.name}.", suffix=given.suffix, dir=folder)
    return fd, Path(name)


def _rename(fd: int, temp: Path, target: Path, *, exclusive: bool = False) -> None:
    """fsync and close ``fd`` (the temporary file), give it its mode, rename it onto
    ``target`` (``exclusive``: link it there, FileExistsError if something is); the
    temporary file is removed if any of that fails."""
    try:
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        try:
            mode = stat.S_IMODE(target.stat().st_mode)
        except FileNotFoundError:
            mode = NEW_MODE
        os.chmod(temp, mode)
        if exclusive:
            os.link(temp, target)
            temp.unlink()
        else:
            os.replace(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


def write_bytes(path: str | Path, data: bytes, *, exclusive: bool = False) -> None:
    """Write ``data`` to ``path`` whole (OSError if it cannot be, the old file kept;
    ``exclusive``: FileExistsError if ``path`` exists, nothing written)."""
    target, in_place = _target(path)
    if exclusive and os.path.lexists(path):
        raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(path))
    if in_place:
        with open(target, "wb") as f:
            f.write(data)
        return
    fd, temp = _temporary(path, target)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    except BaseException:
        os.close(fd)
        temp.unlink(missing_ok=True)
        raise
    _rename(fd, temp, target, exclusive=exclusive)


def write_text(path: str | Path, text: str, *, exclusive: bool = False) -> None:
    """Write ``text`` (UTF-8) to ``path`` whole (``exclusive``: see ``write_bytes``)."""
    write_bytes(path, text.encode("utf-8"), exclusive=exclusive)


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """The name to write ``path`` under: renamed onto ``path`` when the block ends, removed
    if it raises. For a device or FIFO, a temporary file beside the name given, copied
    into it at the end (a library's own error handling cannot hide a full device)."""
    target, in_place = _target(path)
    fd, temp = _temporary(path, target, beside_name=in_place)
    os.close(fd)
    try:
        yield temp
        if in_place:
            with temp.open("rb") as src, open(target, "wb") as dst:
                shutil.copyfileobj(src, dst)
        else:
            _rename(os.open(temp, os.O_RDONLY), temp, target)  # written by name: sync it
    finally:
        temp.unlink(missing_ok=True)          # renamed: nothing left there


class OutputFile:
    """A file written as a run goes, one whole record (a line, a row) per ``write``,
    buffered up to ``buffer_bytes`` [bytes]. No I/O before ``open()``."""

    def __init__(self, path: str | Path, *, buffer_bytes: int = io.DEFAULT_BUFFER_SIZE
                 ) -> None:
        self.path = Path(path)
        self.buffer_bytes = buffer_bytes
        self._fd: int | None = None
        self._temp: Path | None = None
        self._target = self.path
        self._pending: list[bytes] = []
        self._size = 0           # bytes pending
        self._whole = 0          # bytes on the file, in whole records
        self.failure: OSError | None = None   # the first failed write

    def open(self) -> OutputFile:
        """Create the temporary file (or open the device); OSError if it cannot be."""
        self._target, in_place = _target(self.path)
        if in_place:
            self._fd = os.open(self._target, os.O_WRONLY | os.O_TRUNC)
        else:
            self._fd, self._temp = _temporary(self.path, self._target)
        return self

    def write(self, text: str) -> None:
        """Append one whole record; OSError if the file cannot take it (then and for
        every later record: the file keeps the whole records before it)."""
        if self.failure is not None:
            raise self.failure
        data = text.encode("utf-8")
        self._pending.append(data)
        self._size += len(data)
        if self._size >= self.buffer_bytes:
            self._flush()

    def _flush(self) -> None:
        """Write what is pending; on a failure cut the file back to its whole records."""
        assert self._fd is not None
        records, self._pending, self._size = self._pending, [], 0
        data = memoryview(b"".join(records))
        done = 0
        try:
            while done < len(data):
                done += os.write(self._fd, data[done:])
        except OSError as e:
            self.failure = e
            kept = 0
            for r in records:
                if kept + len(r) > done:
                    break
                kept += len(r)
            self._whole += kept
            if self._temp is not None:
                with suppress(OSError):       # a shorter file needs no new block
                    os.ftruncate(self._fd, self._whole)
            raise
        self._whole += done

    def commit(self, *, partial: bool = True) -> None:
        """Flush and rename onto the path (a device: close); OSError if a write failed
        (the file then holds the whole records before it; ``partial`` False, or none
        written: the old file stays)."""
        if self._fd is None:
            return
        if self.failure is None and self._pending:
            with suppress(OSError):           # kept in self.failure, raised below
                self._flush()
        fd, self._fd = self._fd, None
        if self._temp is None:
            os.close(fd)
        elif self.failure is not None and (self._whole == 0 or not partial):
            os.close(fd)
            self._temp.unlink(missing_ok=True)
        else:
            _rename(fd, self._temp, self._target)
        if self.failure is not None:
            raise self.failure

    def discard(self) -> None:
        """Close, and remove the temporary file: whatever was at the path stays."""
        if self._fd is None:
            return
        fd, self._fd = self._fd, None
        os.close(fd)
        if self._temp is not None:
            self._temp.unlink(missing_ok=True)
