"""The file a plot is written to: the formats a plot's name may end in, checked before any
work, and the save (robot.files.atomic: whole, under exactly the name given).

The format is the name's suffix, one of ``FORMATS`` (matplotlib writes each with its own
backends and Pillow; left out: pgf, which needs LaTeX, and raw / rgba, which are pixel
buffers, not pictures). A name without a suffix is written as a PNG under that name
(matplotlib would add ``.png`` to it; we write the name we say).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from robot.files.atomic import replacing

FORMATS = ("png", "pdf", "svg", "svgz", "eps", "ps", "jpg", "jpeg", "tif", "tiff", "webp")
#: The format of a name without a suffix.
DEFAULT = "png"


def figure_format(path: str | Path) -> str:
    """The format a plot named ``path`` is written in; ValueError listing the formats if
    its suffix is none of them."""
    suffix = Path(path).suffix
    if not suffix:
        return DEFAULT
    fmt = suffix[1:].lower()
    if fmt not in FORMATS:
        raise ValueError(f"{suffix!r} is not a picture format a plot is written in; "
                         f"expected a name ending in {', '.join('.' + f for f in FORMATS)}")
    return fmt


def save_figure(fig: Any, path: str | Path, *, dpi: int = 90) -> None:
    """Write the matplotlib figure ``fig`` to ``path`` whole, in its format (OSError if it
    cannot be written: the old file stays)."""
    fmt = figure_format(path)
    with replacing(path) as temp:
        fig.savefig(temp, format=fmt, dpi=dpi)
