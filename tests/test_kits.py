"""The bundled kits are the importer's output: `biped robots import` on the published
models in ../shared/robots/ with the recipes in robot/configs/import/ writes exactly the
bundled robot files, so what is bundled is numbers the importer made from the vendor's
file, never a hand-edited copy."""

from __future__ import annotations

from pathlib import Path

import pytest

import robot.cli as cli

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "robots"
KITS = {"robotis-op3": SHARED / "robotis_op3" / "op3.xml",
        "open-duck-mini-v2": SHARED / "open_duck_mini_v2" / "robot.xml"}


@pytest.mark.parametrize("kit", sorted(KITS))
def test_the_bundled_kit_is_the_importers_output(kit: str, tmp_path: Path) -> None:
    out = tmp_path / f"{kit}.toml"
    recipe = REPO / "robot" / "configs" / "import" / f"{kit}.toml"
    assert cli.main(["robots", "import", str(KITS[kit]), "--missing-meshes", "box",
                     "--map", str(recipe), "--out", str(out)]) == 0
    bundled = REPO / "robot" / "configs" / "robots" / f"{kit}.toml"
    assert out.read_text() == bundled.read_text(), (
        f"robot/configs/robots/{kit}.toml is not what the import writes: run the command at "
        f"the top of {recipe.relative_to(REPO)}")
