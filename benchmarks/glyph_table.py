"""Build matcad/parts/glyphs.json: DejaVu Sans outlines of the printable ASCII characters as matplotlib's TextPath
flattens them (at font size 1), each character's advance and the pairs whose spacing differs from it (kerning) or
that the shaper joins (ligatures), so that :func:`matcad.parts.flat.engraving_outlines` draws engraved labels
without importing matplotlib (its font machinery costs several times numpy's import on a laser-only build).

    python benchmarks/glyph_table.py      # rewrite the table (after a matplotlib upgrade that moves glyphs)

matplotlib flattens curves into more points on larger glyphs, so the table serves engravings up to
matcad.parts.flat.GLYPH_TABLE_MAX_MM tall.
tests/test_fast_pictures.py checks the table against matplotlib on many strings and sizes.
"""

from __future__ import annotations

import json
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "matcad" / "parts" / "glyphs.json"
CHARS = "".join(chr(c) for c in range(32, 127))


def main() -> None:
    from matplotlib import _text_helpers
    from matplotlib.font_manager import FontProperties, findfont, get_font
    from matplotlib.textpath import TextPath, TextToPath

    prop = FontProperties(family="DejaVu Sans")
    font = get_font(findfont(prop))
    font.set_size(TextToPath.FONT_SCALE, TextToPath.DPI)

    def xs(s):
        return [item.x / TextToPath.FONT_SCALE for item in _text_helpers.layout(s, font)]

    glyphs = {}
    for c in CHARS:
        path = None if c.isspace() else TextPath((0.0, 0.0), c, size=1.0, prop=prop)
        polys = [] if path is None else [[[float(x), float(y)] for x, y in poly[:-1]]
                                         for poly in path.to_polygons(closed_only=True) if len(poly) > 3]
        glyphs[c] = {"polygons": polys, "advance": xs(c + "|")[1]}
    kern, joined = {}, []
    for a in CHARS:
        for b in CHARS:
            x = xs(a + b)
            if len(x) != 2:
                joined.append(a + b)
            elif abs(x[1] - glyphs[a]["advance"]) > 1e-12:
                kern[a + b] = x[1]
    OUT.write_text(json.dumps({"about": "DejaVu Sans via matplotlib TextPath at size 1 (benchmarks/glyph_table.py)",
                               "glyphs": glyphs, "pairs": kern, "joined": joined}, separators=(",", ":")),
                   encoding="utf-8")
    print(f"{OUT}: {len(glyphs)} glyphs, {len(kern)} kerned pairs, {len(joined)} joined")


if __name__ == "__main__":
    main()
