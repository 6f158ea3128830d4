"""Issue 36, rows 3 and 10, and what was held already: an animation file that is not one
`biped import` can take is one line naming the file, exit 2, and no take written; a glTF
reads nothing outside its own folder.

The files are ours (`biped export`), then edited by hand: a buffer or image uri pointing
elsewhere, a BIN chunk that says 1e9 bytes, lengths that lie, NaN in an accessor; BVH text
written out here.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import pytest

import robot.cli as cli

ROT = "CHANNELS 3 Zrotation Xrotation Yrotation"


def bvh(frames: int, rows: list[str], *, declared: int | None = None,
        frame_time: str = "0.0333") -> str:
    """A root with one child joint (3 rotations each): ``rows`` of 6 numbers."""
    return "\n".join([
        "HIERARCHY", "ROOT hips", "{", "OFFSET 0 0 0", ROT, "JOINT knee", "{",
        "OFFSET 0 0 -0.4", ROT, "End Site", "{", "OFFSET 0 0 -0.4", "}", "}", "}",
        "MOTION", f"Frames: {frames if declared is None else declared}",
        f"Frame Time: {frame_time}", *rows]) + "\n"


def deep_bvh(depth: int) -> str:
    opening = [f"JOINT j{k}\n{{\nOFFSET 0 0 -0.01\n{ROT}" for k in range(depth)]
    return ("HIERARCHY\nROOT hips\n{\nOFFSET 0 0 0\n" + ROT + "\n" + "\n".join(opening)
            + "\nEnd Site\n{\nOFFSET 0 0 -0.01\n}\n" + "}\n" * (depth + 1)
            + "MOTION\nFrames: 2\nFrame Time: 0.0333\n"
            + " ".join(["0"] * (3 * (depth + 1))) + "\n"
            + " ".join(["0"] * (3 * (depth + 1))) + "\n")


BVHS = {  # name: (text, what the one line says)
    "0 frames": (bvh(0, []), "expected at least one frame"),
    "1 frame": (bvh(1, ["0 0 0 0 0 0"]), "1 frame: a pose, not an animation"),
    "NaN channel": (bvh(2, ["0 0 0 0 0 0", "0 nan 0 0 0 0"]), "MOTION frame 1: a value is not finite"),
    "lying frame count": (bvh(3, ["0 0 0 0 0 0"] * 2, declared=3),
                          "MOTION has 12 numbers; 3 frames of 6 channels need 18"),
    "5000-deep hierarchy": (deep_bvh(5000), "no bone of the map (by name) is in the file"),
}


def run_import(src: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    out = tmp_path / "out.take.jsonl"
    code = cli.main(["import", str(src), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert (code == 0) == out.exists(), err
    return code, err


def refused(code: int, err: str, src: Path, *needles: str) -> None:
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in (str(src), *needles):
        assert n in err, err


@pytest.mark.parametrize("case", sorted(BVHS))
def test_a_bvh_that_is_no_animation_is_one_line(case: str, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    text, needle = BVHS[case]
    src = tmp_path / "bad.bvh"
    src.write_text(text)
    code, err = run_import(src, tmp_path, capsys)
    refused(code, err, src, needle)


# ------------------------------------------------------------------------------ glTF
@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> dict[str, bytes]:
    d = tmp_path_factory.mktemp("exported")
    out = {}
    for name in ("e.gltf", "e.glb"):
        assert cli.main(["export", "--seconds", "0.5", "--out", str(d / name)]) == 0
        out[name] = (d / name).read_bytes()
    return out


def gltf_doc(exported: dict[str, bytes]) -> tuple[dict, bytes]:
    doc = json.loads(exported["e.gltf"])
    uri = doc["buffers"][0]["uri"]
    assert uri.startswith("data:")
    return doc, base64.b64decode(uri.split(",", 1)[1])


def test_a_buffer_in_the_gltf_s_folder_is_read(exported: dict[str, bytes], tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    doc, blob = gltf_doc(exported)
    sub = tmp_path / "sub"
    (sub / "bin").mkdir(parents=True)
    (sub / "bin" / "x.bin").write_bytes(blob)
    doc["buffers"][0]["uri"] = "bin/../bin/x.bin"
    src = sub / "trav.gltf"
    src.write_text(json.dumps(doc))
    code, err = run_import(src, tmp_path, capsys)
    assert code == 0 and err == "", err              # no "orphaned" warning either


#: uri → what the one line says of it.
URIS = {
    "../../secret/x.bin": "leaves the glTF's folder",
    "../sub2/x.bin": "leaves the glTF's folder",
    "link/x.bin": "leaves the glTF's folder",       # a link in the folder to outside it
    "ABSOLUTE": "is an absolute path",
    "file:///etc/passwd": "has a scheme other than data:",
    "http://127.0.0.1:9/x.bin": "has a scheme other than data:",
}


@pytest.mark.parametrize("kind", ["buffers", "images"])
@pytest.mark.parametrize("uri", sorted(URIS))
def test_a_uri_outside_the_folder_is_refused(uri: str, kind: str, exported: dict[str, bytes],
                                             tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """It read ../../secret/x.bin or an absolute path, exit 0."""
    doc, blob = gltf_doc(exported)
    secret = tmp_path / "secret" / "x.bin"
    secret.parent.mkdir()
    secret.write_bytes(blob)
    sub = tmp_path / "a" / "sub"
    sub.mkdir(parents=True)
    (tmp_path / "a" / "sub2").mkdir()
    (tmp_path / "a" / "sub2" / "x.bin").write_bytes(blob)
    (sub / "link").symlink_to(secret.parent)
    text = str(secret) if uri == "ABSOLUTE" else uri
    if kind == "buffers":
        doc["buffers"][0]["uri"] = text
    else:
        doc["images"] = [{"uri": text}]
    src = sub / "trav.gltf"
    src.write_text(json.dumps(doc))
    code, err = run_import(src, tmp_path, capsys)
    refused(code, err, src, f"{kind}[0].uri", URIS[uri])


def glb_chunks(data: bytes) -> tuple[int, int]:
    """(JSON chunk length, offset of the BIN chunk's header) of a .glb."""
    json_len = struct.unpack_from("<I", data, 12)[0]
    return json_len, 12 + 8 + json_len


def nan_gltf(exported: dict[str, bytes]) -> bytes:
    """The first animation output accessor's first float set to NaN."""
    doc, blob = gltf_doc(exported)
    acc = doc["accessors"][doc["animations"][0]["samplers"][0]["output"]]
    view = doc["bufferViews"][acc["bufferView"]]
    at = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    blob = blob[:at] + struct.pack("<f", float("nan")) + blob[at + 4:]
    doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                + base64.b64encode(blob).decode())
    return json.dumps(doc).encode()


def glb_with(exported: dict[str, bytes], case: str) -> bytes:
    g = bytearray(exported["e.glb"])
    _, bin_at = glb_chunks(bytes(g))
    if case == "BIN chunk of 1e9 bytes":
        struct.pack_into("<I", g, bin_at, 10**9)
    elif case == "total length lies":
        struct.pack_into("<I", g, 8, len(g) + 400)
    elif case == "truncated":
        del g[bin_at + 100:]
    return bytes(g)


GLTFS = {  # name: (file name, its bytes from the exported files, what the line says)
    "BIN chunk of 1e9 bytes": ("x.glb", lambda e: glb_with(e, "BIN chunk of 1e9 bytes"),
                               "BIN chunk at byte"),
    "total length lies": ("x.glb", lambda e: glb_with(e, "total length lies"),
                          "its header says"),
    "truncated": ("x.glb", lambda e: glb_with(e, "truncated"), "its header says"),
    "NaN in an accessor": ("x.gltf", nan_gltf, "not finite"),
}


@pytest.mark.parametrize("case", sorted(GLTFS))
def test_a_gltf_that_lies_is_one_line(case: str, exported: dict[str, bytes], tmp_path: Path,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    name, make, needle = GLTFS[case]
    src = tmp_path / name
    src.write_bytes(make(exported))
    code, err = run_import(src, tmp_path, capsys)
    refused(code, err, src, needle)
