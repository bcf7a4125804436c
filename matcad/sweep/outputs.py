"""A sweep's folder, written through :func:`matcad.output.staged_output` (manifest, never half-written):
``sweep.csv`` or ``sweep.parquet`` (the table, written chunk by chunk as the sweep streams it: :data:`TABLES`) and
``sweep.json`` (the axes, units and how it was made, and the rows too when the sweep kept them: up to
:data:`matcad.sweep.grid.MAX_VARIANTS` variants, or any grid of one or two axes). The maps are
:mod:`matcad.sweep.maps`.
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
        block = Block.of(rows)
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
