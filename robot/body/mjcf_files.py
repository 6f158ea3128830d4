"""An MJCF file's text made ready for MuJoCo's compiler: includes expanded, every mesh
looked up and handed over under a name of its own (a stand-in where the file is missing),
textures, height fields and skins dropped (robot/body/mjcf_read.py reads the result)."""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ET
from pathlib import Path

from robot.errors import ConfigError

_DROPPED = ("texture", "hfield", "skin")


def stand_in_stl() -> bytes:
    """A binary STL tetrahedron one unit across (a missing mesh's placeholder)."""
    tris = (((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
            ((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    out = bytearray(b"\0" * 80 + struct.pack("<I", len(tris)))
    for tri in tris:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for v in tri:
            out += struct.pack("<3f", *(float(c) for c in v))
        out += b"\0\0"
    return bytes(out)


def find_file(folder: Path, name: str, warnings: list[str], *, where: str) -> Path | None:
    """``folder / name``, or the one file there whose path differs only in case (with a
    warning); None if there is none."""
    path = folder / name
    if path.is_file():
        return path
    parent = path.parent
    if not parent.is_dir():
        return None
    matches = [p for p in parent.iterdir() if p.name.lower() == path.name.lower() and p.is_file()]
    if len(matches) == 1:
        warnings.append(f"{where}: mesh file {name!r} found as {matches[0].name!r} "
                        "(differs in case)")
        return matches[0]
    return None


def _expand(path: Path, seen: tuple[Path, ...] = ()) -> ET.Element:
    """The file's root element with every ``<include file=...>`` replaced by the included
    file's children (relative to the including file)."""
    try:
        root = ET.parse(path).getroot()
    except OSError as e:
        raise ConfigError(f"{path}: cannot read the model: {e.strerror or e}") from e
    except ET.ParseError as e:
        raise ConfigError(f"{path}: not well-formed XML: {e}") from e
    for parent in list(root.iter()):
        for i, child in enumerate(list(parent)):
            if child.tag != "include":
                continue
            inc = (path.parent / child.get("file", "")).resolve()
            if inc in seen or len(seen) > 16:
                raise ConfigError(f"{path}: include {child.get('file')!r} includes itself")
            parent.remove(child)
            for k, sub in enumerate(list(_expand(inc, (*seen, inc)))):
                parent.insert(i + k, sub)
    return root


def prepare(path: Path, max_hull: int, warnings: list[str]
             ) -> tuple[str, dict[str, bytes], dict[str, tuple[str, str]]]:
    """The XML to compile, its mesh assets, and per stand-in mesh name (the referenced
    file, the mesh's name in the model)."""
    root = _expand(path)
    if root.tag != "mujoco":
        raise ConfigError(f"{path}: not an MJCF file (its root element is <{root.tag}>, "
                          "expected <mujoco>; a URDF? it is read by its .urdf suffix)")
    compiler = root.find("compiler")
    meshdir = assetdir = ""
    if compiler is not None:
        assetdir = compiler.get("assetdir", "")
        meshdir = compiler.get("meshdir", assetdir)
        for key in ("meshdir", "assetdir", "texturedir"):
            compiler.attrib.pop(key, None)
    folder = path.parent / meshdir
    assets: dict[str, bytes] = {}
    missing: dict[str, tuple[str, str]] = {}
    stand_in = stand_in_stl()
    for parent in list(root.iter()):
        for el in list(parent):
            if el.tag in _DROPPED:
                parent.remove(el)
            elif el.tag == "material":
                el.attrib.pop("texture", None)
    for i, mesh in enumerate(root.iter("mesh")):
        ref = mesh.get("file")
        if ref is None:
            continue   # a mesh given by its vertices in the file
        name = mesh.get("name") or Path(ref).stem
        mesh.set("name", name)
        key = f"biped_mesh_{i}{Path(ref).suffix.lower() or '.stl'}"
        mesh.set("file", key)
        mesh.set("maxhullvert", str(max_hull))
        found = find_file(folder, ref, warnings, where=str(path))
        if found is None:
            assets[key] = stand_in
            missing[name] = (ref, name)
        else:
            assets[key] = found.read_bytes()
    return ET.tostring(root, encoding="unicode"), assets, missing


