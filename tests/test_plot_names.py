"""Issue 36, rows 4 and 5: the name of a plot is checked before any work (its suffix is a
picture format we write: robot/previs/figure_file.py), and the name said is the name
written (a name without a suffix: a PNG under that very name, not NAME.png).

The oracle for the formats: matplotlib's own list of what its Agg canvas saves, and each
written file's magic bytes.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from test_bad_input import assert_refused, run_cli

import robot.cli as cli
from robot.previs.figure_file import FORMATS

MAGIC = {"png": b"\x89PNG\r\n\x1a\n", "pdf": b"%PDF-", "jpg": b"\xff\xd8\xff"}


#: command → argv writing a plot named ``name`` (inputs in ``tmp``), the option named.
PLOTTERS = {
    "curves --plot": (lambda tmp, name: ["curves", "--seconds", "1", "--out",
                                         str(tmp / "c.csv"), "--plot", str(tmp / name)],
                      "--plot"),
    "plot --out": (lambda tmp, name: ["plot", str(tmp / "in.csv"), "--out", str(tmp / name)],
                   "--out"),
    "identify check --plot": (lambda tmp, name: [
        "identify", "check", str(tmp / "in.csv"), "--model", "XL330-M288",
        "--plot", str(tmp / name)], "--plot"),
    "play --check-plot": (lambda tmp, name: ["play", str(tmp / "in.csv"), "--check-plot",
                                             str(tmp / name)], "--check-plot"),
    "sim-gap --plot": (lambda tmp, name: ["sim-gap", str(tmp / "in.csv"), "--plot",
                                          str(tmp / name)], "--plot"),
    "robustness --out": (lambda tmp, name: ["robustness", "--out", str(tmp / name)], "--out"),
}


@pytest.mark.parametrize("command", sorted(PLOTTERS))
def test_a_plot_name_that_is_no_picture_is_refused_before_the_work(
        command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A matplotlib ValueError traceback after the work (curves had written c.csv)."""
    (tmp_path / "in.csv").write_text("t\n0\n")
    argv, option = PLOTTERS[command]
    code, out, err = run_cli(argv(tmp_path, "y.txt"), capsys, monkeypatch)
    line = assert_refused(code, err, option, "'.txt' is not a picture format")
    assert all(f".{f}" in line for f in FORMATS), line
    assert out == "" and sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def test_the_formats_are_matplotlib_s() -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    saved = set(FigureCanvasAgg.get_supported_filetypes())
    assert set(FORMATS) <= saved
    assert not {"pgf", "raw", "rgba"} & set(FORMATS)   # LaTeX; pixel buffers


@pytest.mark.parametrize(("name", "kind"), [("noext", "png"), ("c.pdf", "pdf"),
                                            ("c.JPG", "jpg")])
def test_the_name_said_is_the_name_written(name: str, kind: str, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """`--plot noext` said `wrote noext` and wrote noext.png."""
    code, out, err = run_cli(PLOTTERS["curves --plot"][0](tmp_path, name), capsys, monkeypatch)
    assert code == 0, err
    assert f"wrote {tmp_path / name}\n" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["c.csv", name])
    assert (tmp_path / name).read_bytes().startswith(MAGIC[kind])


def test_plot_out_without_a_suffix_is_that_name(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str],
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    record = tmp_path / "run.csv"
    assert cli.main(["walk", "--seconds", "0.3", "--record", str(record)]) == 0
    code, out, err = run_cli(["plot", str(record), "--out", str(tmp_path / "zz")], capsys, monkeypatch)
    assert code == 0, err
    assert f"wrote {tmp_path / 'zz'} " in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "zz"]
    assert (tmp_path / "zz").read_bytes().startswith(MAGIC["png"])
