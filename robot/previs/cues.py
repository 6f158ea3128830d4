"""Cue markers that come with an animation: from a glTF's ``extras``, or a sidecar file.

What an animator's file can carry (checked against the Khronos glTF exporter that ships
with Blender, glTF-Blender-IO): with *Include > Custom Properties* on, an action's custom
properties become its glTF animation's ``extras`` and the scene's become the scene's
``extras`` (a collection's, exporting a collection). Timeline markers and pose markers are
not written (add-ons exist that write them in extensions of their own), and BVH has no
place for anything but the motion. So:

- a custom property ``cue`` on the action (the glTF's first animation, the one imported)
  or else on the scene: either a string ``"2.0 lights up; 4.5 bow"`` (seconds from the
  animation's start, then the name; ``;`` or a new line between cues), what Blender's
  String property holds, or a list of ``{"t": seconds, "name": "..."}``, what a Python
  property (or a script) holds;
- for any format, a sidecar TOML file (``biped import --cues CUES.toml``) of
  ``[[cue]]`` tables with ``t`` [s] and ``name``, the shape of a show's ``[[show.cue]]``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pygltflib as gl

from robot.config.toml_io import JsonValue, read_toml, show
from robot.errors import ConfigError
from robot.motion.show import Cue, parse_show

#: The custom property (glTF ``extras`` key) that holds the cues (as a show's ``cue``).
KEY = "cue"


def _from_text(text: str, where: str) -> list[dict[str, JsonValue]]:
    """``"2.0 lights up; 4.5 bow"`` as cue tables."""
    out: list[dict[str, JsonValue]] = []
    for i, part in enumerate(p.strip() for p in text.replace("\n", ";").split(";")):
        if not part:
            continue
        head, _, name = part.partition(" ")
        try:
            t = float(head)
        except ValueError:
            raise ConfigError(f"{where}.{KEY}[{i}]: {part!r}: expected seconds, then the cue's "
                              "name (e.g. \"2.0 lights up; 4.5 bow\")") from None
        out.append({"t": t, "name": name.strip() or f"cue {i + 1}"})
    return out


def _checked(raw: JsonValue, where: str) -> tuple[Cue, ...]:
    """Cues from a string or a list of ``{t, name}`` (ConfigError naming ``where``)."""
    if isinstance(raw, str):
        raw = _from_text(raw, where)   # type: ignore[assignment]
    if not isinstance(raw, list):
        raise ConfigError(f"{where}.{KEY}: expected \"seconds name; ...\" or a list of "
                          f"{{t, name}}, got {show(raw)}")
    return parse_show({"cue": raw}, where=where).cues


def _extras(item: gl.Animation | gl.Scene | None) -> Mapping[str, JsonValue]:
    extras = getattr(item, "extras", None)
    return extras if isinstance(extras, dict) else {}


def gltf_cues(path: str | Path) -> tuple[Cue, ...]:
    """The cues a .glb / .gltf carries: its first animation's ``extras.cue``, else its
    scene's (none when neither has them). The file was read already (robot/previs/
    gltf_read.py), so a bad file here is a bad cue list only."""
    doc = gl.GLTF2().load(str(path))
    anim = doc.animations[0] if doc and doc.animations else None
    scene = doc.scenes[doc.scene or 0] if doc and doc.scenes else None
    for what, item in (("animations[0]", anim), ("scenes[0]", scene)):
        raw = _extras(item).get(KEY)
        if raw is not None:
            return _checked(raw, f"{path}: {what}.extras")
    return ()


def sidecar_cues(path: str | Path) -> tuple[Cue, ...]:
    """The ``[[cue]]`` tables of a TOML file (ConfigError naming the file and the cue)."""
    p = Path(path)
    data = read_toml(p)
    unknown = sorted(set(data) - {"cue"})
    if unknown:
        raise ConfigError(f"{p}: {unknown[0]}: unknown key; expected [[cue]] tables "
                          "with t (seconds) and name")
    return parse_show({"cue": data.get("cue", [])}, where=str(p)).cues
