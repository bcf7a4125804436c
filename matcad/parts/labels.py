"""Where a board's taxel names go on a part: each label beside its own feature, clear of every hole and sealing
face, inside the part, and nearer its own feature than any other. Pure arithmetic on the glyph box (mm); the
glyphs themselves are drawn by :func:`matcad.parts.flat.engraving_outlines` (laser) or recessed by
:func:`matcad.parts.solid.engraved` (printed).

A maker tells a board's necks, cap holes, mold pockets and needle bores apart by these names; the drawings, the
bill of materials and the fabrication steps use the same names (the taxel's ``name``: t1, t2, ...).
"""

from __future__ import annotations

import functools
from typing import Sequence

from matcad.parts.flat import EM_PER_CAP, Engraving

LABEL_HEIGHTS_MM = (1.5, 1.2, 1.0, 0.8)
"""Capital heights tried, largest first (mm). 0.8 mm is about the smallest a CO2 laser's score or a 0.4 mm nozzle's
recess keeps legible."""
DESCENT = 0.3
ASCENT = 1.05
"""Glyph box of DejaVu Sans relative to the capital height: descenders reach 0.29 below the baseline, 'Ø' 1.04
above it (measured from the glyph outlines)."""
GRID_MM = 0.25
"""Step of the candidate positions searched."""
PRINTED_LABEL_HEIGHTS_MM = (2.0, 1.5)
"""Capital heights of the taxel names recessed in printed parts (mm): DejaVu strokes about 0.09 em, 0.18 mm at
2 mm, a 0.4 mm nozzle's recess still reads."""
PRINTED_LABEL_DEPTH_MM = 0.4
"""Depth of printed labels: two 0.2 mm FDM layers."""


def label_size_mm(text: str, height: float) -> tuple[float, float]:
    """(width, height) of the box that holds ``text`` at capital height ``height`` (mm): the mean advance
    :data:`EM_PER_CAP` per character (over the real outline width for digits and lower case), descenders and the
    'Ø' ring included."""
    return max(len(text), 1) * EM_PER_CAP * height, (DESCENT + ASCENT) * height


def engraving_box(e: Engraving) -> tuple[float, float, float, float]:
    """The glyph box (x0, y0, x1, y1) of an engraving, as :func:`label_size_mm` estimates it (mm)."""
    w, _ = label_size_mm(e.text, e.height)
    return e.x, e.y - DESCENT * e.height, e.x + w, e.y + ASCENT * e.height


def place_labels(wanted: Sequence[tuple[str, float, float]], keepout: Sequence[tuple[float, float, float]],
                 width: float, depth: float, margin: float = 0.5,
                 heights: Sequence[float] = LABEL_HEIGHTS_MM,
                 taken: Sequence[Engraving] = ()) -> tuple[Engraving, ...]:
    """One engraving per (text, x, y) of ``wanted`` on a ``width`` x ``depth`` part centred on the origin (mm).

    Each label takes the largest of ``heights`` that fits and, at that height, the position nearest its anchor
    (x, y) on a :data:`GRID_MM` grid whose glyph box lies inside the part by ``margin``, at least ``margin`` from
    every ``keepout`` circle (x, y, radius: holes, cap flanges) and every label placed before it, and nearer its
    own anchor than any other anchor (so it cannot be read as a neighbour's), and clear of the engravings already
    ``taken``. A label that fits nowhere is left out: :func:`missing_labels` names it."""
    boxes = tuple(((x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 2, (y1 - y0) / 2)
                  for x0, y0, x1, y1 in map(engraving_box, taken))
    return _place(tuple((str(t), float(x), float(y)) for t, x, y in wanted),
                  tuple((float(x), float(y), float(r)) for x, y, r in keepout), float(width), float(depth),
                  float(margin), tuple(float(h) for h in heights), boxes)


@functools.lru_cache(maxsize=256)
def _place(wanted, keepout, width, depth, margin, heights, boxes) -> tuple[Engraving, ...]:
    import numpy as np

    anchors = np.array([(x, y) for _, x, y in wanted]).reshape(-1, 2)
    placed: list[tuple[float, float, float, float]] = list(boxes)  # centre x, y, half width, half height
    out = []
    for i, (text, ax, ay) in enumerate(wanted):
        others = np.delete(anchors, i, axis=0)
        for height in heights:
            w, h = label_size_mm(text, height)
            nx, ny = int((width - w) / 2 / GRID_MM), int((depth - h) / 2 / GRID_MM)
            if nx < 0 or ny < 0:
                continue
            cx, cy = (g.ravel() * GRID_MM for g in np.meshgrid(np.arange(-nx, nx + 1), np.arange(-ny, ny + 1)))
            ok = (np.abs(cx) + w / 2 + margin <= width / 2) & (np.abs(cy) + h / 2 + margin <= depth / 2)
            own = np.hypot(cx - ax, cy - ay)
            for x, y in others:
                ok &= np.hypot(cx - x, cy - y) > own
            for x, y, r in keepout:  # distance from the circle's centre to the glyph box
                gap = np.hypot(np.maximum(np.abs(cx - x) - w / 2, 0), np.maximum(np.abs(cy - y) - h / 2, 0))
                ok &= gap >= r + margin
            for x, y, hw, hh in placed:
                ok &= (np.abs(cx - x) >= hw + w / 2 + margin) | (np.abs(cy - y) >= hh + h / 2 + margin)
            if ok.any():
                k = int(np.argmin(np.where(ok, own, np.inf)))
                placed.append((float(cx[k]), float(cy[k]), w / 2, h / 2))
                baseline = float(cy[k]) - h / 2 + DESCENT * height
                out.append(Engraving(round(float(cx[k]) - w / 2, 6), round(baseline, 6), height, text))
                break
    return tuple(out)


def missing_labels(wanted: Sequence[tuple[str, float, float]], placed: Sequence[Engraving]) -> list[str]:
    """The texts of ``wanted`` that :func:`place_labels` could not place."""
    have = {e.text for e in placed}
    return [text for text, _, _ in wanted if text not in have]
