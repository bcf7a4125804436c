"""A sweep's design-space maps (``maps/*.png``), drawn with :mod:`matcad.canvas` (Pillow; no matplotlib, whose
import and figure machinery cost more than the sweep of a 20 000-variant grid): one picture per quantity — f0,
band low, band high, df0/dfield per axis, rule errors. One axis: a line over the field with f0's band shaded and
rule-failing variants marked ×. Two axes: a heat map (viridis) with a colour bar, variants with rule errors hatched,
invalid or failed variants blank; each cell spans the midpoints to its neighbours (half a step beyond the ends), at
any spacing and in any order the axes' values were given. Three or more axes, or a sweep that kept no rows: the
table only. Each PNG carries its axes in its text chunks (``matcad:x``, ``matcad:y``, ``matcad:quantity``) for
readers and tests. Values in the quantity's unit (Hz, Hz per the field's unit, counts); pictures in pixels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from matcad.sweep.run import SweepResult, sensitivity_column

SIZE = (640, 480)
"""Picture size (px)."""
BOX = (86, 58, 500, 420)
"""The plot's box (left, top, right, bottom px) of a heat map; a line plot runs on to :data:`LINE_RIGHT`."""
LINE_RIGHT = 620
BAR = (516, 532)
"""The colour bar's left and right edges (px), as tall as :data:`BOX`."""
BLUE, RED = "#1f77b4", "#d62728"
HATCH = (255, 255, 255)
"""The hatching over cells with design-rule errors (white: no colour of the map is white)."""


def quantities(result: SweepResult) -> list[tuple[str, str, str]]:
    """(column, file stem, axis label) of every mapped quantity."""
    out = [("f0_hz", "f0", f"f0 [Hz] ({result.model})"), ("band_low_hz", "band_low", "band low [Hz]"),
           ("band_high_hz", "band_high", "band high [Hz]")]
    out += [(sensitivity_column(a), f"df0_d_{a.field}", f"df0/d({a.field}) [Hz/{a.unit or 'unit'}]")
            for a in result.axes]
    if result.rules:
        out.append(("rule_errors", "rule_errors", "design-rule errors"))
    return out


def label(axis) -> str:
    """An axis's label: its field and unit."""
    return f"{axis.field} [{axis.unit}]" if axis.unit else axis.field


def write_maps(result: SweepResult, folder: Path) -> list[str]:
    """The design-space maps into ``folder/maps``; returns their names (none for three or more axes)."""
    from matcad.canvas import saved_together

    if len(result.axes) not in (1, 2) or result.tally is not None:
        return []
    (folder / "maps").mkdir()
    errors = result.column("rule_errors") if result.rules else np.zeros(result.shape)
    names = []
    with saved_together():
        for column, stem, text in quantities(result):
            name = f"maps/{stem}.png"
            draw = _line if len(result.axes) == 1 else _heat_map
            canvas, x_label, y_label = draw(result, column, text, errors)
            canvas.save(folder / name, {"matcad:x": x_label, "matcad:y": y_label, "matcad:quantity": column})
            names.append(name)
    return names


def edges(values) -> np.ndarray:
    """Cell edges around ascending grid values (midpoints; half a step beyond the ends; ±0.5 for a single value)."""
    v = np.asarray(values, dtype=float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def _span(values, pad: float = 0.05) -> tuple[float, float]:
    """The finite values' range widened by ``pad`` of it each way ((0, 1) when none is finite; ±0.5 if one)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return 0.0, 1.0
    lo, hi = float(v.min()), float(v.max())
    margin = pad * (hi - lo) if hi > lo else 0.5 * max(abs(lo), 1.0)
    return lo - margin, hi + margin


def _line(result: SweepResult, column: str, text: str, errors):
    """One axis: the quantity over the field, f0's band shaded, variants with rule errors marked ×."""
    from matcad.canvas import Canvas, tint

    axis = result.axes[0]
    order = np.argsort(np.asarray(axis.values, dtype=float), kind="stable")
    x = np.asarray(axis.values, dtype=float)[order]
    values, bad = result.column(column)[order], (errors > 0)[order]
    band = (result.column("band_low_hz")[order], result.column("band_high_hz")[order]) if column == "f0_hz" else None
    canvas = Canvas(*SIZE)
    ax = canvas.axes((BOX[0], BOX[1], LINE_RIGHT, BOX[3]), _span(x), _span(np.concatenate(
        [values, *(band or ())])))
    ax.frame(xlabel=label(axis), ylabel=text, grid="xy")  # first: the data over the grid
    legend = []
    if band is not None:
        low, high = band
        shade = tint(BLUE, 0.25)
        for run in _finite_runs(x, low, high):
            ax.polygon([(x[k], low[k]) for k in run] + [(x[k], high[k]) for k in reversed(run)], shade)
        legend.append(("band", shade, "bar"))
    ax.line(x, values, BLUE, 2)
    for xv, yv in zip(x, values):
        if np.isfinite(yv):
            ax.marker(xv, yv, "o", BLUE, 3)
    for xv, yv in zip(x[bad], values[bad]):
        if np.isfinite(yv):
            ax.marker(xv, yv, "x", RED, 5)
    if bad.any():
        legend.append(("rule errors", RED, "x"))
    ax.legend(legend)
    return canvas, label(axis), text


def _finite_runs(x, low, high) -> list[list[int]]:
    """Index runs where x, low and high are all finite (a band's shading breaks where a variant has none)."""
    runs, run = [], []
    for k, ok in enumerate(np.isfinite(x) & np.isfinite(low) & np.isfinite(high)):
        if ok:
            run.append(k)
        elif run:
            runs.append(run)
            run = []
    return runs + ([run] if run else [])


def _heat_map(result: SweepResult, column: str, text: str, errors):
    """Two axes: the quantity as coloured cells (the last axis across, the first up) with a colour bar, cells with
    rule errors hatched, invalid or failed ones blank."""
    from matcad.canvas import VIRIDIS, Canvas, colour_map, nice_ticks, tick_label

    y_axis, x_axis = result.axes
    rows = np.argsort(np.asarray(y_axis.values, dtype=float), kind="stable")
    cols = np.argsort(np.asarray(x_axis.values, dtype=float), kind="stable")
    values = result.column(column)[np.ix_(rows, cols)]
    xe, ye = edges(np.asarray(x_axis.values, dtype=float)[cols]), edges(np.asarray(y_axis.values, dtype=float)[rows])
    finite = np.isfinite(values)
    lo, hi = (float(values[finite].min()), float(values[finite].max())) if finite.any() else (0.0, 1.0)
    canvas = Canvas(*SIZE)
    ax = canvas.axes(BOX, (xe[0], xe[-1]), (ye[0], ye[-1]))
    ax.cells(xe, ye, colour_map(np.where(finite, values, lo), lo, hi, VIRIDIS), blank=~finite,
             hatch=errors[np.ix_(rows, cols)] > 0, hatch_colour=HATCH)
    ax.frame(xlabel=label(x_axis), ylabel=label(y_axis), size=11,
             title=f"{text}\nhatched: design-rule errors; blank: invalid or failed")
    top, bottom = BOX[1], BOX[3]
    bar = canvas.axes((BAR[0], top, BAR[1], bottom), (0.0, 1.0), (lo, hi) if hi > lo else (lo - 0.5, hi + 0.5))
    ramp = np.linspace(bar.ylim[1], bar.ylim[0], bottom - top)[:, None]
    bar.image(colour_map(ramp, lo, hi, VIRIDIS))
    canvas.draw.rectangle((BAR[0], top, BAR[1], bottom), outline="black")
    ticks = nice_ticks(*bar.ylim)
    for v in ticks:
        py = bar.y(v)
        canvas.draw.line([(BAR[1], py), (BAR[1] + 4, py)], fill="black")
        canvas.text(BAR[1] + 7, py, tick_label(v, ticks), 10, anchor="lm")
    widest = max(canvas.text_width(tick_label(v, ticks), 10) for v in ticks)
    canvas.vertical_text(BAR[1] + 16 + widest, (top + bottom) / 2, text, 11)
    return canvas, label(x_axis), label(y_axis)
