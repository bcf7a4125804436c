"""A sweep's folder, written through :func:`matcad.output.staged_output` (manifest, never half-written):
``sweep.csv`` or ``sweep.parquet`` (the table, written chunk by chunk as the sweep streams it: :data:`TABLES`) and
``sweep.json`` (the axes, units and how it was made, and the rows too when the sweep kept them: up to
:data:`matcad.sweep.grid.MAX_VARIANTS` variants, or any grid of one or two axes) and ``maps/*.png``.

Maps (matplotlib, imported here only): one figure per quantity — f0, band low, band high, df0/dfield per axis,
rule errors. One axis: a line over the field, rule-failing variants marked ×. Two axes: a heat map, variants with
rule errors hatched, invalid or failed variants blank. Three or more axes: the table only. Each PNG carries its
axes in its text chunks (``matcad:x``, ``matcad:y``, ``matcad:quantity``) for readers and tests.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

from matcad.sweep.run import LOAD_SENSITIVITY, Block, SweepResult, sensitivity_column, table_columns


def _cells(values: list, blank="") -> list:
    """A column's values with ``blank`` for what has no value (None, NaN and other non-finite floats): "" in the
    CSV, None (null) in the JSON."""
    isfinite = math.isfinite
    return [blank if v is None or (isinstance(v, float) and not isfinite(v)) else v for v in values]


def table_dict(result: SweepResult, table: str | None = None) -> dict:
    """The JSON document: how the sweep was made, the axes with units, the counts, and every row (NaN → null)
    when the sweep kept them (else ``rows_in``: the table's file name)."""
    from matcad import __version__

    columns = result.columns()
    doc = {"matcad": __version__, "spec": result.name, "model": result.model,
           "vectorised": result.vectorised, "executor": result.executor, "rules": result.rules,
           "seconds": round(result.seconds, 3), "worker_seconds": round(result.worker_seconds, 3),
           "axes": [{"field": a.field, "unit": a.unit, "values": list(a.values)} for a in result.axes],
           "sensitivity": {sensitivity_column(a): f"df0/d({a.field}) in Hz per {a.unit or 'unit'}"
                           for a in result.axes} | {LOAD_SENSITIVITY: "df0/dF at 0 N by paper Eq. 5 and the "
                                                                      "spec's [calibration] (Hz/N)"},
           "columns": columns}
    if result.tally is not None:
        return {**doc, "variants": result.variants, "counts": result.counts(),
                "rows_in": table or CsvTable.name}
    values = [_cells([row.get(k) for row in result.rows], None) for k in columns]
    return {**doc, "rows": [dict(zip(columns, row)) for row in zip(*values)]}


class TableWriter:
    """The table in ``folder``, written chunk by chunk (call it with each chunk's rows, a
    :class:`~matcad.sweep.run.Block` or row dicts; blank where a variant has no value); the columns are fixed by
    the first chunk (:func:`matcad.sweep.run.table_columns`). A format is a subclass in :data:`TABLES`: it opens
    its file and writes one block's columns."""

    name = ""
    """The file's name in the folder."""

    def __init__(self, folder: Path, axes, rules: bool):
        self.path, self.axes, self.rules = Path(folder) / self.name, tuple(axes), rules
        self.columns = None

    def __call__(self, rows) -> None:
        block = rows if isinstance(rows, Block) else Block.from_rows(rows)
        if self.columns is None:
            self.columns = table_columns(self.axes, self.rules, [dict.fromkeys(block.columns)])
            self._open()
        self._write(block)

    def close(self) -> list[str]:
        if self.columns is None:
            self([])
        self._close()
        return [self.name]


class CsvTable(TableWriter):
    """``sweep.csv``: written a column at a time; the only work per cell is blanking what has no value (None, NaN)
    before the csv module formats it (floats as repr); an axis's values, which repeat down the grid, are formatted
    once each."""

    name = "sweep.csv"

    def __init__(self, folder: Path, axes, rules: bool):
        super().__init__(folder, axes, rules)
        self.axis_cells = {a.field: {v: str(v) for v in a.values} for a in self.axes}

    def _open(self) -> None:
        self.file = open(self.path, "w", newline="", encoding="utf-8")
        self.writer = csv.writer(self.file)
        self.writer.writerow(self.columns)

    def _column(self, block: Block, name: str) -> list:
        values = block.columns.get(name)
        if values is None:
            return [""] * len(block)
        known = self.axis_cells.get(name)
        if known is not None and all(v in known for v in set(values)):
            return [known[v] for v in values]
        return _cells(values)

    def _write(self, block: Block) -> None:
        self.writer.writerows(zip(*(self._column(block, k) for k in self.columns)))

    def _close(self) -> None:
        self.file.close()


class ParquetTable(TableWriter):
    """``sweep.parquet`` (Apache Parquet, by pyarrow: the optional extra ``matcad[parquet]``): a row group per
    chunk, typed columns (:func:`parquet_type`), null where the CSV is blank (None, NaN). For grids too large to
    format as text: the CSV spends ~1 µs a number on its repr, this table ~0.1 µs."""

    name = "sweep.parquet"

    def _open(self) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.schema = pa.schema([(k, parquet_type(k, self.axes)) for k in self.columns])
        self.writer = pq.ParquetWriter(self.path, self.schema)

    def _write(self, block: Block) -> None:
        import pyarrow as pa

        n = len(block)
        arrays = [pa.array(block.columns.get(f.name, [None] * n), type=f.type, from_pandas=True) for f in self.schema]
        self.writer.write_table(pa.Table.from_arrays(arrays, schema=self.schema))

    def _close(self) -> None:
        self.writer.close()


TEXT_COLUMNS = ("status", "reason", "model", "failing_rules")
COUNT_COLUMNS = ("index", "rule_errors", "rule_warnings", "cad_triangles")
FLAG_COLUMNS = ("model_valid", "cad_watertight")


def parquet_type(column: str, axes):
    """The Parquet type of a column of the table: text, counts (int64), flags (bool), an axis as its values are
    (int64 for an integer field) and every other column a float64 (Hz, Hz per unit, mm³)."""
    import pyarrow as pa

    axis = next((a for a in axes if a.field == column), None)
    if column in TEXT_COLUMNS:
        return pa.string()
    if column in COUNT_COLUMNS or (axis is not None and axis.integer):
        return pa.int64()
    return pa.bool_() if column in FLAG_COLUMNS else pa.float64()


TABLES = {"csv": CsvTable, "parquet": ParquetTable}
"""The table's formats (`matcad sweep --table`), by name."""


def table_format(fmt: str) -> type[TableWriter]:
    """The writer of table format ``fmt`` (:data:`TABLES`). Raises ValueError naming the option for an unknown
    format, or for Parquet without pyarrow."""
    if fmt not in TABLES:
        raise ValueError(f"--table {fmt!r} invalid, must be one of {', '.join(TABLES)}")
    if fmt == "parquet":
        import importlib.util

        if importlib.util.find_spec("pyarrow") is None:
            raise ValueError("--table parquet needs pyarrow: pip install 'matcad[parquet]'")
    return TABLES[fmt]


def write_json(result: SweepResult, folder: Path, table: str | None = None) -> list[str]:
    """sweep.json into ``folder`` (one row a line, by json's C encoder), ``table`` the table's file name (default
    the CSV's); returns its name."""
    doc = table_dict(result, table)
    rows = doc.pop("rows", None)
    if rows is None:
        text = json.dumps(doc, indent=1, allow_nan=False)
    else:
        head = json.dumps({**doc, "rows": []}, indent=1, allow_nan=False)
        body = ",\n  ".join(json.dumps(row, allow_nan=False) for row in rows)
        cut = head.rindex("[]")
        text = head[:cut] + (f"[\n  {body}\n ]" if rows else "[]") + head[cut + 2:]
    (folder / "sweep.json").write_text(text + "\n", encoding="utf-8")
    return ["sweep.json"]


def quantities(result: SweepResult) -> list[tuple[str, str, str]]:
    """(column, file stem, axis label) of every mapped quantity."""
    out = [("f0_hz", "f0", f"f0 [Hz] ({result.model})"), ("band_low_hz", "band_low", "band low [Hz]"),
           ("band_high_hz", "band_high", "band high [Hz]")]
    out += [(sensitivity_column(a), f"df0_d_{a.field}", f"df0/d({a.field}) [Hz/{a.unit or 'unit'}]")
            for a in result.axes]
    if result.rules:
        out.append(("rule_errors", "rule_errors", "design-rule errors"))
    return out


def _label(axis) -> str:
    return f"{axis.field} [{axis.unit}]" if axis.unit else axis.field


def write_maps(result: SweepResult, folder: Path) -> list[str]:
    """The design-space maps into ``folder/maps``; returns their names (none for three or more axes)."""
    if len(result.axes) not in (1, 2) or result.tally is not None:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as Outline

    (folder / "maps").mkdir()
    errors = result.column("rule_errors") if result.rules else np.zeros(result.shape)
    names = []
    for column, stem, label in quantities(result):
        values = result.column(column)
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
        x_axis = result.axes[-1] if len(result.axes) == 2 else result.axes[0]
        if len(result.axes) == 1:
            x = np.array(x_axis.values)
            ax.plot(x, values, "o-", ms=3, color="tab:blue")
            if column == "f0_hz":
                ax.fill_between(x, result.column("band_low_hz"), result.column("band_high_hz"), alpha=0.25,
                                label="band")
            bad = errors > 0
            if bad.any():
                ax.plot(x[bad], values[bad], "x", color="tab:red", ms=8, label="rule errors")
            if ax.get_legend_handles_labels()[0]:
                ax.legend()
            y_label = label
        else:
            y_axis = result.axes[0]
            mesh = ax.pcolormesh(_edges(x_axis.values), _edges(y_axis.values), np.ma.masked_invalid(values),
                                 shading="flat", cmap="viridis")
            fig.colorbar(mesh, ax=ax, label=label)
            xe, ye = _edges(x_axis.values), _edges(y_axis.values)
            cells = [Outline([(xe[j], ye[i]), (xe[j + 1], ye[i]), (xe[j + 1], ye[i + 1]), (xe[j], ye[i + 1]),
                           (xe[j], ye[i])], closed=True) for i, j in zip(*np.nonzero(errors > 0))]
            if cells:  # every hatched cell in one path: one fill however large the grid; added as an artist, not
                # a patch, so its thousands of vertices are not walked again for limits the mesh has already set
                ax.add_artist(PathPatch(Outline.make_compound_path(*cells), fill=False, hatch="///",
                                        edgecolor="white", linewidth=0.0))
            ax.set_title(f"{label}\nhatched: design-rule errors; blank: invalid or failed", fontsize=10)
            y_label = _label(y_axis)
        ax.set_xlabel(_label(x_axis))
        ax.set_ylabel(y_label)
        name = f"maps/{stem}.png"
        fig.savefig(folder / name, dpi=100, metadata={"matcad:x": _label(x_axis), "matcad:y": y_label,
                                                      "matcad:quantity": column})
        plt.close(fig)
        names.append(name)
    return names


def _edges(values) -> "np.ndarray":
    """Cell edges around grid values (midpoints; half a step beyond the ends; ±0.5 for a single value)."""
    import numpy as np

    v = np.asarray(values, dtype=float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
