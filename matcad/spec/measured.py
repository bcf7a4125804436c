"""The [[measured]] tables: taxels a lab built from this design (or a variant of it) and measured, the data that
measured-beats-modelled predictions are anchored to (docs/inference.md). Lengths mm, frequencies Hz, forces N.

Each entry names the drawing it was built from where that differs from this spec (the fields left out are this
spec's own, as loaded), what was measured of the part itself (a calipered sheet, a pin-gauged neck) and what it
sang: the unloaded f0, f(F) pairs under a pressing plate, force–displacement pairs. Files that ``matcad analyze``
and ``matcad calibrate`` read or write are turned into these numbers when the spec is loaded
(:mod:`matcad.spec.io`), so a validated spec holds numbers only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from matcad.spec.drawn import Drawn, drawn_spec
from matcad.spec.fields import LENGTH_MAX_MM, MISSING, Section, SpecError, length_mm, param

FILE_FIELDS = {
    "analysis": (("f0_hz", "f0_tolerance_hz"), "a single-taxel report.json `matcad analyze` wrote: f0_hz is its "
                 "median_hz, f0_tolerance_hz its std_hz"),
    "calibration_data": (("force_n", "f_hz"), "a CSV of f(F) pairs with force_n and frequency_hz columns (what "
                         "`matcad calibrate` reads)"),
    "force_displacement": (("displacement_mm", "displacement_force_n"), "a CSV of force-displacement pairs with "
                           "displacement_mm and force_n columns"),
}
"""File keys a [[measured]] table may give instead of numbers → (the fields they fill, what the file is); paths are
relative to the spec's folder and read when the spec is loaded."""


def _series(doc: str, unit: str, lo: float, hi: float) -> object:
    return param(doc, unit, None, kind="vector", lo=lo, hi=hi, lo_open=False)


@dataclass(frozen=True)
class Measured(Drawn, Section):
    """One built and measured taxel. Give at least one of: ``f0_hz`` (or ``analysis``), f(F) pairs (``force_n`` with
    ``f_hz``, or ``calibration_data``), force–displacement pairs (``displacement_mm`` with ``displacement_force_n``,
    or ``force_displacement``)."""

    table: ClassVar[str] = "measured"

    name: str | None = param("this taxel's name in the inference's report; default m<i> (1-based, in file order)",
                             default=None, kind="name")
    f0_hz: float | None = param("its measured unloaded resonance (the median `matcad analyze` reports; or give "
                                "analysis = \"REPORT.json\", the report.json analyze wrote)", "Hz", None,
                                lo=0.0, hi=1e7)
    f0_tolerance_hz: float = param("standard uncertainty of that f0 (1 sd: the tone's wander over the recording, "
                                   "not the FFT bin)", "Hz", 20.0, lo=0.0, hi=1e7)
    temperature_c: float | None = param("air temperature when it was measured; default [air] temperature_c "
                                        "(then +-3 degC is added to the uncertainty)", "degC", None,
                                        lo=-273.15, hi=1000.0)
    measured_neck_diameter: float | None = length_mm(
        "its neck as built, the mean of both faces (pin gauges, a microscope); informs the neck offset", None)
    measured_neck_taper: float | None = param(
        "its neck's diameter at the mouth minus at the cavity, as built (a laser cuts wider where it enters)", "mm",
        None, lo=-LENGTH_MAX_MM, hi=LENGTH_MAX_MM, lo_open=False)
    measured_sheet: float | None = length_mm("its neck sheet as calipered; informs the sheet offset", None)
    force_n: tuple[float, ...] | None = _series(
        "forces of its f(F) pairs (or give calibration_data = \"DATA.csv\", the CSV `matcad calibrate` reads)", "N",
        0.0, 1e6)
    f_hz: tuple[float, ...] | None = _series("frequencies of its f(F) pairs, one per force", "Hz", 1e-3, 1e7)
    displacement_mm: tuple[float, ...] | None = _series(
        "plate travel of its force-displacement pairs, from where the stage read zero (or give force_displacement "
        "= \"FX.csv\" with displacement_mm and force_n columns)", "mm", -LENGTH_MAX_MM, LENGTH_MAX_MM)
    displacement_force_n: tuple[float, ...] | None = _series("forces of its force-displacement pairs, one per "
                                                             "displacement", "N", 0.0, 1e6)

    def __post_init__(self) -> None:
        super().__post_init__()
        for xs, ys, x_name, y_name in ((self.force_n, self.f_hz, "force_n", "f_hz"),
                                       (self.displacement_mm, self.displacement_force_n, "displacement_mm",
                                        "displacement_force_n")):
            if (xs is None) != (ys is None):
                given, missing = (x_name, y_name) if ys is None else (y_name, x_name)
                raise SpecError(f"measured.{missing}", MISSING, f"is required with measured.{given} (pairs)")
            if xs is not None and len(xs) != len(ys):
                raise SpecError(f"measured.{y_name}", f"{len(ys)} values",
                                f"must pair with measured.{x_name}: {len(xs)} values")
        if self.f0_hz is None and self.force_n is None and self.displacement_mm is None:
            raise SpecError("measured.f0_hz", MISSING, "is required unless f(F) pairs (force_n, f_hz) or "
                                                    "force-displacement pairs are given: a measured taxel needs data")
        if self.f0_hz is not None and not self.f0_tolerance_hz < self.f0_hz:
            raise SpecError("measured.f0_tolerance_hz", self.f0_tolerance_hz,
                            f"must be < measured.f0_hz = {self.f0_hz:g} Hz")

    @property
    def label(self) -> str:
        """Its name (the caller numbers unnamed entries)."""
        return self.name or ""


def measured_spec(spec, entry: Measured):
    """The spec of the drawing ``entry`` was built from: ``spec`` (as loaded) with the entry's drawn geometry, with no
    [reference], [calibration] or [[measured]] of its own (it is not itself anchored)."""
    return drawn_spec(spec, entry, reference=None, calibration=None, measured=(), array=None, taxel=())


def resolve_files(entries, base_dir) -> list:
    """The raw [[measured]] tables with their file keys (``analysis``, ``calibration_data``, ``force_displacement``,
    paths relative to the spec's folder ``base_dir``) replaced by the numbers they hold; raises SpecError naming the
    entry's key on a file that cannot be read."""
    from pathlib import Path

    if not isinstance(entries, list):
        return entries
    out = []
    for i, raw in enumerate(entries, 1):
        if not isinstance(raw, dict):
            out.append(raw)
            continue
        table = dict(raw)
        for key, (filled, _) in FILE_FIELDS.items():
            if key not in table:
                continue
            where = f"measured[{i}].{key}"
            given = [f for f in filled if f in table and (key != "analysis" or f == "f0_hz")]
            if given:
                raise SpecError(where, table[key], f"give either {key} or {', '.join(given)}, not both")
            value = table.pop(key)
            if not isinstance(value, str) or not value:
                raise SpecError(where, value, "must be a file path (text), relative to the spec's folder")
            path = Path(value) if Path(value).is_absolute() else Path(base_dir) / value
            table.update(_READERS[key](path, where))
        out.append(table)
    return out


def _analysis(path, where: str) -> dict:
    """f0 and its uncertainty from a single-taxel report.json of `matcad analyze`: the median and the sd of the
    tracked tone."""
    import json

    from matcad.errors import InputError
    from matcad.inputs import read_text

    try:
        report = json.loads(read_text(path, "analysis report", 16 << 20))
    except (InputError, ValueError, RecursionError) as exc:
        raise SpecError(where, str(path), f"must be a readable report.json of `matcad analyze` ({exc})") from None
    if not isinstance(report, dict) or not isinstance(report.get("median_hz"), (int, float)):
        raise SpecError(where, str(path), "must be a single-taxel report.json of `matcad analyze` (no median_hz)")
    sd = report.get("std_hz")
    return {"f0_hz": float(report["median_hz"])} | ({"f0_tolerance_hz": float(sd)}
                                                     if isinstance(sd, (int, float)) and sd > 0 else {})


def _pairs(path, where: str, x_col: str, y_col: str, x_key: str, y_key: str) -> dict:
    """Two columns of a CSV file with a header naming them (``#`` comment lines skipped)."""
    import csv

    from matcad.errors import InputError
    from matcad.inputs import CSV_MAX_BYTES, read_text

    try:
        rows = [r for r in csv.reader(read_text(path, "measured data", CSV_MAX_BYTES).splitlines())
                if r and not r[0].lstrip().startswith("#")]
    except (InputError, csv.Error) as exc:
        raise SpecError(where, str(path), f"must be a readable CSV file ({exc})") from None
    head = [c.strip().lower() for c in rows[0]] if rows else []
    if x_col not in head or y_col not in head:
        raise SpecError(where, str(path), f"must be a CSV whose header names {x_col} and {y_col}")
    i, j = head.index(x_col), head.index(y_col)
    xs, ys = [], []
    for line, row in enumerate(rows[1:], 2):
        try:
            xs.append(float(row[i]))
            ys.append(float(row[j]))
        except (ValueError, IndexError):
            raise SpecError(where, str(path), f"row {line} must hold numbers in {x_col} and {y_col}") from None
    if not xs:
        raise SpecError(where, str(path), "must hold at least one row of data")
    return {x_key: xs, y_key: ys}


_READERS = {
    "analysis": _analysis,
    "calibration_data": lambda p, w: _pairs(p, w, "force_n", "frequency_hz", "force_n", "f_hz"),
    "force_displacement": lambda p, w: _pairs(p, w, "displacement_mm", "force_n", "displacement_mm",
                                              "displacement_force_n"),
}
