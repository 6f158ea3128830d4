"""`biped plot`: run records (.csv, .jsonl) and curves CSVs to PNG, told apart by columns."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from robot.cli import main
from robot.errors import ConfigError
from robot.previs.plots import kind_of, read_table


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("plot")
    out = {"csv": d / "run.csv", "jsonl": d / "run.jsonl", "curves": d / "curves.csv"}
    for key in ("csv", "jsonl"):
        assert main(["walk", "--seconds", "0.5", "--rate", "100", "--read-every", "2",
                     "--record", str(out[key]), "--json"]) == 0
    assert main(["curves", "--seconds", "1", "--rate", "50", "--out", str(out["curves"])]) == 0
    return out


@pytest.mark.parametrize("key, kind", [("csv", "record"), ("jsonl", "record"),
                                       ("curves", "curves")])
def test_plot_writes_a_png(files: dict[str, Path], key: str, kind: str, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    table = read_table(files[key])
    assert kind_of(table) == kind
    if kind == "record":
        assert np.isfinite(table.columns["present_r_knee"]).sum() > 10
        assert np.isfinite(table.columns["temp_r_knee"]).sum() > 10
    png = tmp_path / "out.png"
    capsys.readouterr()
    assert main(["plot", str(files[key]), "--out", str(png)]) == 0
    assert f"{kind} plot" in capsys.readouterr().out
    assert png.stat().st_size > 50_000
    img = imread(png)
    assert img.shape[0] > 800 and img.shape[1] > 800 and img[..., :3].std() > 0.05


def test_plot_refuses_other_files(tmp_path: Path) -> None:
    bad = tmp_path / "other.csv"
    bad.write_text("t,x\n0,1\n1,2\n")
    with pytest.raises(ConfigError, match="neither a run record"):
        kind_of(read_table(bad))
    assert main(["plot", str(bad), "--out", str(tmp_path / "o.png")]) == 2
    assert main(["plot", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "o.png")]) == 2
    assert not (tmp_path / "o.png").exists()
