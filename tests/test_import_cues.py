"""Cue markers that come with an animation reach the take: a glTF written with pygltflib as
Blender's exporter writes custom properties (an action's as its animation's ``extras``, the
scene's as the scene's), in the two forms an animator can type (a String property, a
Python list), and a sidecar TOML file for any format (BVH has no place for them); a bad
cue is one line naming the file and the cue, exit 2, and no take written."""

from __future__ import annotations

import json
from pathlib import Path

import pygltflib as gl
import pytest
from anim_files import map_toml, write_blender_bvh, write_blender_gltf

import robot.cli as cli

FPS, FRAMES = 30.0, 45


def _gltf(tmp_path: Path, *, animation: object = None, scene: object = None) -> Path:
    """A Blender-style .glb with ``extras`` set as Blender's exporter sets them."""
    src = tmp_path / "dance.glb"
    write_blender_gltf(str(src), FPS, FRAMES)
    doc = gl.GLTF2().load(str(src))
    if animation is not None:
        doc.animations[0].extras = {"cue": animation, "author": "someone"}
    if scene is not None:
        doc.scenes[0].extras = {"cue": scene}
    doc.save_binary(str(src))
    return src


def _import(tmp_path: Path, src: Path, *extra: str) -> int:
    bones = tmp_path / "map.toml"
    bones.write_text(map_toml())
    return cli.main(["import", str(src), "--map", str(bones),
                     "--out", str(tmp_path / "d.take.jsonl"), *extra])


def _bvh_with_sidecar(tmp_path: Path, toml: str) -> int:
    """Import a Blender-style BVH with the sidecar cue file ``toml`` (its text)."""
    src, side = tmp_path / "dance.bvh", tmp_path / "dance.cues.toml"
    write_blender_bvh(str(src), FPS, FRAMES)
    side.write_text(toml)
    return cli.main(["import", str(src), "--out", str(tmp_path / "d.take.jsonl"),
                     "--cues", str(side)])


def _cues(tmp_path: Path) -> list[tuple[float, str]]:
    header = json.loads((tmp_path / "d.take.jsonl").read_text().splitlines()[0])
    return [(c["t"], c["name"]) for c in header["show"]["cue"]]


def test_an_action_s_cue_list_becomes_the_take_s_cues(tmp_path: Path) -> None:
    src = _gltf(tmp_path, animation=[{"t": 1.25, "name": "bow"}, {"t": 0.5, "name": "up"}],
                scene="9 not this one")
    assert _import(tmp_path, src) == 0
    assert _cues(tmp_path) == [(0.5, "up"), (1.25, "bow")]


def test_a_scene_s_cue_string_when_the_action_has_none(tmp_path: Path) -> None:
    src = _gltf(tmp_path, scene="0.5 lights up; 1.0 bow\n1.4 lights out")
    assert _import(tmp_path, src) == 0
    assert _cues(tmp_path) == [(0.5, "lights up"), (1.0, "bow"), (1.4, "lights out")]


def test_a_sidecar_file_gives_a_bvh_its_cues(tmp_path: Path) -> None:
    assert _bvh_with_sidecar(tmp_path, '[[cue]]\nt = 0.75\nname = "jump"\n\n[[cue]]\n'
                             't = 0.25\nname = "hop"\n') == 0
    assert _cues(tmp_path) == [(0.25, "hop"), (0.75, "jump")]


def test_no_cues_anywhere_gives_none(tmp_path: Path) -> None:
    assert _import(tmp_path, _gltf(tmp_path)) == 0
    assert _cues(tmp_path) == []


@pytest.mark.parametrize(("animation", "said"), [
    ("soon bow", "animations[0].extras.cue[0]: 'soon bow': expected seconds"),
    ([{"t": "x", "name": "bow"}], "animations[0].extras: cue[0].t: expected a number"),
    (3, "animations[0].extras.cue: expected"),
])
def test_a_bad_cue_is_one_line_and_nothing_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], animation: object,
        said: str) -> None:
    src = _gltf(tmp_path, animation=animation)
    assert _import(tmp_path, src) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and str(src) in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "d.take.jsonl").exists()


def test_a_sidecar_with_other_keys_is_refused(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    assert _bvh_with_sidecar(tmp_path, '[[cues]]\nt = 1.0\nname = "bow"\n') == 2
    err = capsys.readouterr().err.strip()
    assert "cues: unknown key" in err and len(err.splitlines()) == 1, err
