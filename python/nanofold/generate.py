"""Generated crease patterns (the families ``nanofold generate`` writes); lengths in the
sheet's units, angles in degrees.

>>> import nanofold
>>> p = nanofold.generate.miura(3, 5, angle_deg=70)
>>> p.describe()["panels"]
15
"""

from __future__ import annotations

from typing import Any, Optional

from . import _native
from ._core import Pattern, _call, _settings

__all__ = ["miura", "square_twist", "waterbomb", "bird_base"]


def _generate(kind: str, name: str, **parameters: Any) -> Pattern:
    text = _call(_native.generate, kind, _settings(parameters))
    return Pattern(text, name, origin=f"<generated {name}>")


def miura(
    rows: int = 4,
    cols: int = 4,
    *,
    angle_deg: float = 60.0,
    width: float = 1.0,
    slant: float = 1.0,
    fold_deg: Optional[float] = None,
) -> Pattern:
    """Miura-ori of rows × cols parallelogram panels with acute angle ``angle_deg``; with
    ``fold_deg``, folded with its zigzag creases at that angle (closed form)."""
    name = f"miura_{rows}x{cols}"
    return _generate("miura", name, rows=rows, cols=cols, angle_deg=angle_deg, width=width, slant=slant, fold_deg=fold_deg)


def square_twist(side: float = 1.0, half_sheet: float = 1.5, *, twist_deg: float = 30.0, flip_pleats: bool = False) -> Pattern:
    """Square twist: a central square and four pleats turned by ``twist_deg`` (1 to 45)."""
    return _generate("square_twist", "square_twist", side=side, half_sheet=half_sheet, twist_deg=twist_deg, flip_pleats=flip_pleats)


def waterbomb(rows: int = 2, cols: int = 2, *, row_height: float = 1.0) -> Pattern:
    """Waterbomb tessellation of degree-6 vertices (``row_height`` ≠ 1: Huffman's rectangular cells)."""
    return _generate("waterbomb", f"waterbomb_{rows}x{cols}", rows=rows, cols=cols, row_height=row_height)


def bird_base(half_side: float = 1.0) -> Pattern:
    """The bird base's flat-foldable crease pattern on a square of half side ``half_side``."""
    return _generate("bird_base", "bird_base", half_side=half_side)

