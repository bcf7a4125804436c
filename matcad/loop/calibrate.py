"""Calibrating a taxel from measured force/frequency pairs: read the data (CSV), fit paper Eq. 5 with K from the
as-built geometry (:func:`matcad.acoustics.eq5fit.fit`), and draw the fit with its bands and residuals. Forces N,
frequencies Hz, volumes mm³.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from matcad.acoustics.eq5fit import Eq5Fit

FORCE_LIMIT_N = 1e6
"""|F| above this is not a taxel load (and F² would overflow the fit): the spec's calibration.force_range_n bound."""
FREQUENCY_LIMIT_HZ = 1e7
"""The spec's microphone.sample_rate_hz bound: no recorded tone lies above it."""
FREQUENCY_MIN_HZ = 1e-3
"""No tone a microphone records lies below 1 mHz (a column in kHz, 4.5, still passes and gets a unit note)."""
_DECIMAL_COMMA = re.compile(r"^\s*[+-]?\d+,\d+\s*$")


def _european(row: list[str]) -> str:
    """Why a row that holds no two numbers may be a European-locale CSV (';' between columns, ',' as the decimal
    mark, as Excel writes it in many locales), or '' if it does not look like one."""
    if any(";" in cell for cell in row) or any(_DECIMAL_COMMA.match(cell) for cell in row):
        return ("; it looks like a European-locale CSV (';' between columns, ',' as the decimal mark): save it "
                "with ',' between columns and '.' as the decimal mark (e.g. 0.5,4500.5)")
    return ""


def read_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Force (N), frequency (Hz) and, when the header names one, load-cycle label columns: a header naming force_n
    and frequency_hz (and optionally cycle), or the first two columns. The file is size-limited before parsing
    (:data:`matcad.inputs.CSV_MAX_BYTES`); raises ValueError."""
    from matcad.errors import shorten
    from matcad.inputs import CSV_MAX_BYTES, read_text

    text = read_text(path, "calibration data", CSV_MAX_BYTES)
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:  # a field over csv.field_size_limit() (131 072 characters), a NUL byte
        raise ValueError(f"calibration data {path}: not a readable CSV file ({exc})") from None
    rows = [r for r in rows if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise ValueError(f"calibration data {path}: no rows")
    head = [c.strip().lower() for c in rows[0]]
    i_f, i_hz, start, i_c = 0, 1, 0, None
    if "force_n" in head and "frequency_hz" in head:
        i_f, i_hz, start = head.index("force_n"), head.index("frequency_hz"), 1
        i_c = head.index("cycle") if "cycle" in head else None
    forces, freqs, cycles = [], [], []
    for line, row in enumerate(rows[start:], start + 1):
        try:
            force, freq = float(row[i_f]), float(row[i_hz])
        except (ValueError, IndexError):
            raise ValueError(f"calibration data {path}, row {line}: {shorten(row)} must hold a force (N) and a "
                             f"frequency (Hz){_european(row)}") from None
        if not (abs(force) <= FORCE_LIMIT_N and FREQUENCY_MIN_HZ <= freq <= FREQUENCY_LIMIT_HZ):
            raise ValueError(f"calibration data {path}, row {line}: force {force!r} must be finite with |F| <= "
                             f"{FORCE_LIMIT_N:g} N and frequency {freq!r} finite, {FREQUENCY_MIN_HZ:g} <= f <= "
                             f"{FREQUENCY_LIMIT_HZ:g} Hz")
        forces.append(force)
        freqs.append(freq)
        if i_c is not None:
            label = row[i_c].strip() if i_c < len(row) else ""
            if not label or len(label) > 64:
                raise ValueError(f"calibration data {path}, row {line}: cycle {shorten(label)!r} must name the load "
                                 "cycle (1-64 characters)")
            cycles.append(label)
    return np.array(forces), np.array(freqs), (np.array(cycles) if i_c is not None else None)


def fit_from_spec(forces_n, frequencies_hz, spec, k_free: bool = False, cycles=None,
                  temperature_c: float | None = None, cycle_std_n: float | None = None) -> Eq5Fit:
    """Fit with K (or V0, when ``k_free``) from the spec's as-built geometry and air; ``temperature_c`` (°C)
    is the air's during calibration (default the spec's [air] temperature_c). See :func:`matcad.acoustics.eq5fit.fit`
    for the cycles, the assumed between-cycle scatter and when it refuses (LoopError)."""
    from matcad.acoustics.design import design
    from matcad.acoustics.eq5 import frequency_constant_mm3_hz2
    from matcad.acoustics.eq5fit import fit
    from matcad.acoustics.resonator import resonator

    d = design(spec)
    res = resonator(d)
    k = float(frequency_constant_mm3_hz2(res.c_m_s, d.neck_diameter, d.neck_length))
    temp = spec.air.temperature_c if temperature_c is None else temperature_c
    return fit(forces_n, frequencies_hz, k, res.volume if k_free else None, cycles, temp, cycle_std_n)


def plot(fitted: Eq5Fit, path: Path) -> None:
    """Fit with 95 % confidence and prediction bands, and the residuals (Hz), as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cal = fitted.law
    grid = np.linspace(*cal.force_range_n, 200)
    c_lo, c_hi, p_lo, p_hi = cal.frequency_bands_hz(grid)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.5, 6), sharex=True, height_ratios=(2, 1))
    top.fill_between(grid, p_lo, p_hi, alpha=0.2, label="95 % prediction band")
    top.fill_between(grid, c_lo, c_hi, alpha=0.4, label="95 % confidence band")
    top.plot(grid, cal.frequency_hz(grid), label="Eq. 5 fit")
    top.plot(fitted.forces_n, fitted.frequencies_hz, "ko", ms=4, label="data")
    top.set(ylabel="frequency [Hz]", title="matcad calibrate")
    top.legend(fontsize=8)
    bottom.axhline(0, color="grey")
    bottom.plot(fitted.forces_n, fitted.frequencies_hz - cal.frequency_hz(fitted.forces_n), "ko", ms=4)
    bottom.set(xlabel="force [N]", ylabel="residual [Hz]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
