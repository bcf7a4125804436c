"""A sweep's design-space maps (``maps/*.png``), drawn with :mod:`matcad.canvas` (Pillow; no matplotlib, whose
import and figure machinery cost more than the sweep of a 20 000-variant grid) from the sweep's stream:
:class:`Planes` is a sink of :func:`matcad.sweep.run.sweep` that keeps, chunk by chunk as the table streams, only
the values the maps show. One picture per quantity — f0, band low, band high, df0/dfield per axis of the map, rule
errors. One axis: a line over the field with f0's band shaded and rule-failing variants marked ×. Two axes: a heat
map (viridis) with a colour bar, variants with rule errors hatched, invalid or failed variants blank; each cell
spans the midpoints to its neighbours (half a step beyond the ends), at any spacing and in any order the axes'
values were given. Three or more axes: the heat maps of every pair of axes through the grid's middle, every other
axis at the median of its values (named in the title), in ``maps/<first field>-<second field>/``. A map holds at
most :data:`matcad.sweep.grid.MAX_POINTS` ² values a quantity, whatever the grid's size. Each PNG carries its axes
in its text chunks (``matcad:x``, ``matcad:y``, ``matcad:quantity``, and ``matcad:held`` for a slice) for readers
and tests. Values in the quantity's unit (Hz, Hz per the field's unit, counts); pictures in pixels.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from matcad.sweep.run import Block, sensitivity_column

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


def quantities(axes, rules: bool, model: str = "") -> list[tuple[str, str, str]]:
    """(column, file stem, axis label) of every quantity mapped over ``axes`` (a map's one or two axes): f0 (by
    ``model``), the band's edges, df0/d of each of those axes, and the rule errors when the sweep judged rules."""
    out = [("f0_hz", "f0", f"f0 [Hz] ({model})"), ("band_low_hz", "band_low", "band low [Hz]"),
           ("band_high_hz", "band_high", "band high [Hz]")]
    out += [(sensitivity_column(a), f"df0_d_{a.field}", f"df0/d({a.field}) [Hz/{a.unit or 'unit'}]") for a in axes]
    if rules:
        out.append(("rule_errors", "rule_errors", "design-rule errors"))
    return out


class Plane:
    """What one group of maps shows: its ``axes`` (one, or two with the first up), the grid's other axes held at
    ``held`` ({axis: value}), and each quantity's values (:func:`quantities`) at the map's grid points, in the axes'
    given order (NaN where a variant has no value: invalid, failed, not judged, or not yet streamed)."""

    def __init__(self, axes, held: dict, rules: bool):
        self.axes, self.held, self.rules = tuple(axes), held, rules
        shape = tuple(len(a.values) for a in self.axes)
        self.values = {column: np.full(shape, np.nan) for column, _, _ in quantities(self.axes, rules)}

    def column(self, name: str) -> np.ndarray:
        return self.values[name]

    def errors(self) -> np.ndarray:
        """Design-rule errors per grid point (0 where the sweep judged no rules or the variant has no verdict)."""
        return np.nan_to_num(self.values["rule_errors"]) if self.rules else np.zeros(self.values["f0_hz"].shape)

    def held_text(self) -> str:
        """The held axes as the title names them, e.g. 'cavity.length = 4.5 mm' ('' for none)."""
        return ", ".join(f"{a.field} = {v:g}{f' {a.unit}' if a.unit else ''}" for a, v in self.held.items())

    def folder(self) -> str:
        """The maps' folder under maps/: '' for the grid's own axes, '<first field>-<second field>' for a slice."""
        return "-".join(a.field for a in self.axes) if self.held else ""


class Planes:
    """A sweep's sink that keeps what its maps show (:class:`Plane`): the whole grid of one or two axes; of three
    or more, each pair of axes with every other axis at its median value (the lower of the two middle values of an
    even count). Called with each chunk's rows (a :class:`~matcad.sweep.run.Block` or row dicts, as
    :func:`matcad.sweep.run.sweep` streams them); keeps the rows that lie on a plane, whatever the grid's size."""

    def __init__(self, axes, rules: bool):
        self.axes = tuple(axes)
        self.shape = tuple(len(a.values) for a in self.axes)
        k = len(self.axes)
        middle = [_median_index(a.values) for a in self.axes]
        self.planes: list[tuple[tuple[int, ...], dict[int, int], Plane]] = []
        for pair in [tuple(range(k))] if k <= 2 else itertools.combinations(range(k), 2):
            held = {m: middle[m] for m in range(k) if m not in pair}
            values = {self.axes[m]: self.axes[m].values[i] for m, i in held.items()}
            self.planes.append((pair, held, Plane([self.axes[m] for m in pair], values, rules)))

    def __call__(self, rows) -> None:
        block = Block.of(rows)
        if not len(block):
            return
        at = np.unravel_index(np.asarray(block.columns["index"], dtype=np.int64), self.shape)
        for pair, held, plane in self.planes:
            on = np.flatnonzero(np.logical_and.reduce([at[m] == i for m, i in held.items()])) if held else \
                np.arange(len(block))
            if not on.size:
                continue
            where = tuple(at[m][on] for m in pair)
            for name, values in plane.values.items():
                column = block.columns.get(name)
                if column is not None:
                    values[where] = np.array([column[r] for r in on.tolist()], dtype=float)  # None: NaN


def _median_index(values) -> int:
    """Index of the median of ``values`` (the lower middle one of an even count), in their given order."""
    order = np.argsort(np.asarray(values, dtype=float), kind="stable")
    return int(order[(len(values) - 1) // 2])


def label(axis) -> str:
    """An axis's label: its field and unit."""
    return f"{axis.field} [{axis.unit}]" if axis.unit else axis.field


def write_maps(planes: Planes, folder: Path, model: str) -> list[str]:
    """The design-space maps of the streamed ``planes`` into ``folder/maps``, f0 labelled by ``model``; returns
    their names."""
    from matcad.canvas import saved_together

    names = []
    for _, _, plane in planes.planes:
        where = Path("maps") / plane.folder()
        (folder / where).mkdir(parents=True, exist_ok=True)
        with saved_together():  # a plane's pictures at a time: 6 held, ~5 MB, whatever the number of pairs
            for column, stem, text in quantities(plane.axes, plane.rules, model):
                draw = _line if len(plane.axes) == 1 else _heat_map
                canvas, x_label, y_label = draw(plane, column, text)
                chunks = {"matcad:x": x_label, "matcad:y": y_label, "matcad:quantity": column}
                if plane.held:
                    chunks["matcad:held"] = "; ".join(f"{a.field}={v}" for a, v in plane.held.items())
                canvas.save(folder / where / f"{stem}.png", chunks)
                names.append((where / f"{stem}.png").as_posix())
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


def _line(plane: Plane, column: str, text: str):
    """One axis: the quantity over the field, f0's band shaded, variants with rule errors marked ×."""
    from matcad.canvas import Canvas, tint

    axis = plane.axes[0]
    order = np.argsort(np.asarray(axis.values, dtype=float), kind="stable")
    x = np.asarray(axis.values, dtype=float)[order]
    values, bad = plane.column(column)[order], (plane.errors() > 0)[order]
    band = (plane.column("band_low_hz")[order], plane.column("band_high_hz")[order]) if column == "f0_hz" else None
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


def _heat_map(plane: Plane, column: str, text: str):
    """Two axes: the quantity as coloured cells (the last axis across, the first up) with a colour bar, cells with
    rule errors hatched, invalid or failed ones blank; a slice names the other axes' values in its title."""
    from matcad.canvas import VIRIDIS, Canvas, colour_map, nice_ticks, tick_label

    y_axis, x_axis = plane.axes
    rows = np.argsort(np.asarray(y_axis.values, dtype=float), kind="stable")
    cols = np.argsort(np.asarray(x_axis.values, dtype=float), kind="stable")
    values = plane.column(column)[np.ix_(rows, cols)]
    xe, ye = edges(np.asarray(x_axis.values, dtype=float)[cols]), edges(np.asarray(y_axis.values, dtype=float)[rows])
    finite = np.isfinite(values)
    lo, hi = (float(values[finite].min()), float(values[finite].max())) if finite.any() else (0.0, 1.0)
    if hi <= lo:  # one value everywhere (a field f0 does not read): mid-scale, in the cells as on the bar
        lo, hi = lo - 0.5, hi + 0.5
    canvas = Canvas(*SIZE)
    ax = canvas.axes(BOX, (xe[0], xe[-1]), (ye[0], ye[-1]))
    ax.cells(xe, ye, colour_map(np.where(finite, values, lo), lo, hi, VIRIDIS), blank=~finite,
             hatch=plane.errors()[np.ix_(rows, cols)] > 0, hatch_colour=HATCH)
    held = f"\nat {plane.held_text()}" if plane.held else ""
    ax.frame(xlabel=label(x_axis), ylabel=label(y_axis), size=11,
             title=f"{text}{held}\nhatched: design-rule errors; blank: invalid or failed")
    top, bottom = BOX[1], BOX[3]
    bar = canvas.axes((BAR[0], top, BAR[1], bottom), (0.0, 1.0), (lo, hi))
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
