"""A real full disk for tests: a small tmpfs mounted under the test's ``tmp_path`` and
filled to its last block, so a write there fails with ENOSPC as on a full SD card (a
stand-in like /dev/full is not a directory and has free space). Mounting needs root, as
CI has (Debian, root). Use with ``pytest_plugins = ("full_disk",)``.
"""

from __future__ import annotations

import errno
import os
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

#: Size of the tmpfs: a few pages; the fill takes all of them.
SIZE = "64k"


#: Bytes left free by ``nearly_full_dir``: a few lines fit, a take or a picture does not.
LEFT = 8192


def _filled(d: Path, *, leave: int) -> Iterator[Path]:
    """A tmpfs mounted on ``d`` and filled to ``leave`` bytes of free space."""
    d.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={SIZE},mode=0777",
                              "tmpfs", str(d)], capture_output=True, text=True)
    if mounted.returncode:
        pytest.fail(f"a full-disk test mounts a {SIZE} tmpfs, which needs root (CI runs as "
                    f"root): {mounted.stderr.strip()}")
    try:
        fd = os.open(d / ".fill", os.O_WRONLY | os.O_CREAT, 0o600)
        try:
            while True:
                os.write(fd, b"\0" * 4096)
        except OSError as e:
            assert e.errno == errno.ENOSPC, e
        finally:
            if leave:
                os.ftruncate(fd, max(0, os.fstat(fd).st_size - leave))
            os.close(fd)
        free = os.statvfs(d).f_bavail * os.statvfs(d).f_frsize
        assert free == leave, (free, leave)
        yield d
    finally:
        subprocess.run(["umount", "-l", str(d)], check=False)


@pytest.fixture
def full_dir(tmp_path: Path) -> Iterator[Path]:
    """An empty-looking directory on a disk with no block left (files can be created,
    nothing can be written into them)."""
    yield from _filled(tmp_path / "full", leave=0)


@pytest.fixture
def nearly_full_dir(tmp_path: Path) -> Iterator[Path]:
    """A directory on a disk with ``LEFT`` bytes free: a command's output check passes
    (there is space), and a file larger than that fails part-way (ENOSPC)."""
    yield from _filled(tmp_path / "nearly", leave=LEFT)
