"""A long BVH import (issue 34): memory follows the output, not the input's text; a long
import shows its progress; an animation beyond what can be imported is one line, exit 2,
nothing written.

The bound is shown without a 200 MB file: two BVHs with the same frames (so the same take),
one written compactly and one with every number padded to 300 characters (45 MB of text).
Reading text as Python words cost about 1.4 bytes of memory per byte of text (100-character
numbers; at 300, ``open().read().split()`` of the padded file peaks 85 MB over the compact
one's); parsed as a stream into arrays the two imports peak within a few MB of each other. Peak RSS is the
``biped import`` subprocess's own (``resource.getrusage`` of the waited-for child, one child
per measuring process).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from anim_files import KNEE_HIERARCHY

REPO = Path(__file__).resolve().parent.parent
HEAD = KNEE_HIERARCHY
FPS = 120.0
#: 83 s: a 20,000-tick take at 240 Hz. The text's size, not the take's length, is what the
#: bound is about; 30,000 frames padded to 100 characters made the same 45 MB of text and
#: three times the take to import (4.3 s an import, the file's 13 s of 7 CPU-s).
FRAMES = 10_000
PAD = 296                # zeros after each number's one decimal: 300 characters a number
#: Measures ``biped import`` in a child of its own and prints its peak RSS [kB].
PEAK = ("import resource, subprocess, sys; r = subprocess.run(sys.argv[1:], "
        "capture_output=True, text=True); sys.stderr.write(r.stderr); "
        "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")


def write_bvh(path: Path, *, pad: int, frames: int = FRAMES) -> None:
    """Our skeleton's names, the right knee swinging 10-50 deg at 1 decimal."""
    t = np.arange(frames) / FPS
    rows = np.zeros((frames, 15))
    rows[:, 1] = 25.0
    rows[:, 11] = np.round(30.0 + 20.0 * np.sin(2.0 * t), 1)
    text = np.char.add(np.char.mod("%.1f", rows), "0" * pad)
    with path.open("w") as f:
        f.write("\n".join([*HEAD, f"Frames: {frames}", f"Frame Time: {1 / FPS:.6f}"]) + "\n")
        f.writelines(" ".join(r) + "\n" for r in text.tolist())


def imported(src: Path, out: Path) -> tuple[int, int, str]:
    """(exit code, peak RSS [kB], stderr) of `biped import SRC --out OUT`."""
    r = subprocess.run([sys.executable, "-c", PEAK, sys.executable, "-m", "robot.cli",
                        "import", str(src), "--out", str(out)], cwd=REPO, capture_output=True,
                       text=True, timeout=300)
    code, kb = (int(v) for v in r.stdout.split())
    return code, kb, r.stderr


def test_memory_follows_the_take_not_the_text(tmp_path: Path) -> None:
    compact, padded = tmp_path / "compact.bvh", tmp_path / "padded.bvh"
    write_bvh(compact, pad=0)
    write_bvh(padded, pad=PAD)
    extra_text = padded.stat().st_size - compact.stat().st_size
    assert extra_text > 40e6
    code_c, kb_c, _ = imported(compact, tmp_path / "c.take.jsonl")
    code_p, kb_p, err = imported(padded, tmp_path / "p.take.jsonl")
    assert code_c == code_p == 0, err
    assert (tmp_path / "c.take.jsonl").read_bytes().split(b"\n")[1:] == \
        (tmp_path / "p.take.jsonl").read_bytes().split(b"\n")[1:]      # the same take
    # Words of text: +59 MB here (main before this change); streamed: within 15 MB.
    assert (kb_p - kb_c) * 1024 < 15e6, (kb_c, kb_p, extra_text)
    assert "reading padded.bvh" in err                    # a long read shows its progress


def test_an_animation_too_long_to_import_is_one_line(tmp_path: Path) -> None:
    """The header's frame count decides, before a frame is read: 2 h at 120 fps."""
    src, out = tmp_path / "long.bvh", tmp_path / "long.take.jsonl"
    src.write_text("\n".join([*HEAD, "Frames: 864000", f"Frame Time: {1 / FPS:.6f}",
                              "0 " * 15]) + "\n")
    r = subprocess.run([sys.executable, "-m", "robot.cli", "import", str(src), "--out",
                        str(out)], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    (line,) = r.stderr.strip().splitlines()
    assert str(src) in line and "864000 frames" in line and "3600 s" in line, line
    assert not out.exists() and list(tmp_path.iterdir()) == [src]
