"""robot/files/atomic.py, the one way a file is written, on real disks: a tmpfs with a few
kilobytes left (tests/full_disk.py), a link, /dev/full. A write that does not fit leaves
the old file as it was and no temporary file; a file written as a run goes keeps exactly
the whole records that fitted (the records are the oracle: their concatenation, cut at a
record boundary)."""

from __future__ import annotations

import errno
import stat
from pathlib import Path

import pytest
from full_disk import LEFT

from robot.files.atomic import OutputFile, replacing, write_bytes, write_text

pytest_plugins = ("full_disk",)

OLD = "the old file, whole\n"


def names(d: Path) -> list[str]:
    return sorted(p.name for p in d.iterdir())


def test_a_file_is_replaced_whole_with_its_mode(tmp_path: Path) -> None:
    path = tmp_path / "x.toml"
    path.write_text(OLD)
    path.chmod(0o600)
    write_text(path, "new = 1\n")
    assert path.read_text() == "new = 1\n"
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    assert names(tmp_path) == ["x.toml"]
    write_text(tmp_path / "fresh.toml", "a = 2\n")
    assert stat.S_IMODE((tmp_path / "fresh.toml").stat().st_mode) == 0o644


def test_a_write_that_does_not_fit_keeps_the_old_file(nearly_full_dir: Path) -> None:
    path = nearly_full_dir / "x.csv"
    path.write_text(OLD)
    with pytest.raises(OSError) as e:
        write_bytes(path, b"y" * (4 * LEFT))
    assert e.value.errno == errno.ENOSPC
    assert path.read_text() == OLD
    assert names(nearly_full_dir) == [".fill", "x.csv"]


def test_a_library_that_fails_leaves_the_old_file(tmp_path: Path) -> None:
    path = tmp_path / "x.png"
    path.write_text(OLD)
    with pytest.raises(RuntimeError), replacing(path) as temp:
        assert temp.parent == tmp_path and temp.suffix == ".png" and temp != path
        temp.write_text("half a picture")
        raise RuntimeError("the library failed")
    assert path.read_text() == OLD
    assert names(tmp_path) == ["x.png"]


def test_a_link_is_followed_and_stays_a_link(tmp_path: Path) -> None:
    target = tmp_path / "data" / "real.csv"
    target.parent.mkdir()
    target.write_text(OLD)
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    write_text(link, "new\n")
    assert link.is_symlink() and target.read_text() == "new\n"
    assert names(target.parent) == ["real.csv"]


def test_a_device_is_written_in_place(tmp_path: Path) -> None:
    """/dev/full cannot be renamed onto: it is written, and its ENOSPC raised, by every
    shape; the link stays."""
    link = tmp_path / "full.mp4"
    link.symlink_to("/dev/full")
    with pytest.raises(OSError) as e:
        write_text(link, "x")
    assert e.value.errno == errno.ENOSPC
    with pytest.raises(OSError) as e, replacing(link) as temp:
        temp.write_bytes(b"a clip")
    assert e.value.errno == errno.ENOSPC
    out = OutputFile(link, buffer_bytes=1).open()
    with pytest.raises(OSError):
        out.write("a row\n")
    with pytest.raises(OSError):
        out.commit()
    assert link.is_symlink() and names(tmp_path) == ["full.mp4"]


def test_exclusive_never_replaces(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(OLD)
    with pytest.raises(FileExistsError):
        write_text(path, "other\n", exclusive=True)
    assert path.read_text() == OLD and names(tmp_path) == ["mine.toml"]
    write_text(tmp_path / "new.toml", "a = 1\n", exclusive=True)
    assert (tmp_path / "new.toml").read_text() == "a = 1\n"


def test_a_run_that_fills_the_disk_keeps_its_whole_records(nearly_full_dir: Path) -> None:
    path = nearly_full_dir / "run.take.jsonl"
    out = OutputFile(path, buffer_bytes=1000).open()
    records = [f'{{"tick": {k}, "q": [{k * 0.001:.6f}, 0.25, -0.5]}}\n' for k in range(2000)]
    written = 0
    with pytest.raises(OSError) as e:
        for r in records:
            out.write(r)
            written += 1
    assert e.value.errno == errno.ENOSPC and written < len(records)
    with pytest.raises(OSError):
        out.commit()
    text = path.read_text()
    whole = "".join(records)
    assert text and whole.startswith(text) and text.endswith("\n")
    assert text.count("\n") <= written and len(text) <= LEFT
    assert names(nearly_full_dir) == [".fill", "run.take.jsonl"]


def test_a_run_that_never_started_leaves_the_old_file(tmp_path: Path) -> None:
    path = tmp_path / "keep.csv"
    path.write_text(OLD)
    out = OutputFile(path).open()
    out.write("t,state\n")
    assert len(names(tmp_path)) == 2                # the temporary file, beside it
    out.discard()
    assert path.read_text() == OLD and names(tmp_path) == ["keep.csv"]
    out = OutputFile(path).open()
    out.write("t,state\n")
    out.write("0.0,walking\n")
    out.commit()
    assert path.read_text() == "t,state\n0.0,walking\n" and names(tmp_path) == ["keep.csv"]
    with pytest.raises(FileNotFoundError):            # opened before the run: it fails first
        OutputFile(tmp_path / "gone" / "other.csv").open()
