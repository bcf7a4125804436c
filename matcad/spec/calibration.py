"""The [calibration] table: paper Eq. 5 constants fitted to a taxel's recordings, and what sensing needs of them.

A calibration is read from a spec's [calibration], a [[taxel]]'s [taxel.calibration] sub-table or a calibration
file of its own (``matcad calibrate`` writes them). Volumes in mm^3, forces in N.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from matcad.spec.drawn import Drawn
from matcad.spec.fields import LENGTH_MIN_MM, Section, SpecError, param


@dataclass(frozen=True)
class Calibration(Drawn, Section):
    """Paper Eq. 5 constants: V_eff = v0_mm3 - a F^2 - b F (F in N)."""

    table: ClassVar[str] = "calibration"

    v0_mm3: float = param("effective unloaded cavity volume V_ci (at least the smallest cavity a spec allows, "
                          "(1e-3 mm)^3)", "mm^3", lo=LENGTH_MIN_MM ** 3, hi=1e18, lo_open=False)
    a: float = param("quadratic deflection coefficient a (paper: -0.0086)", "mm^3/N^2",
                     lo=-1e12, hi=1e12, lo_open=False)
    b: float = param("linear deflection coefficient b (paper: 0.4626)", "mm^3/N",
                     lo=-1e12, hi=1e12, lo_open=False)
    area_convention: str = param(
        "neck area used with v0: 'pi_d2/4' (physical, A = pi d^2/4) or 'd2/4' (the paper's fit, "
        "see docs/paper.md)", default="pi_d2/4", kind="choice", choices=("pi_d2/4", "d2/4"))
    k_mm3_hz2: float | None = param("K = c^2 A / (4 pi^2 l) the fit used; when given it replaces the one "
                                    "computed from the neck and area_convention (written by `matcad calibrate`)",
                                    "mm^3 Hz^2", None, lo=0.0, hi=1e30)
    force_range_n: tuple[float, float] | None = param(
        "[low, high] forces the calibration was measured over; `sense` gives no force outside it", "N", None,
        kind="range", lo=-1e6, hi=1e6, lo_open=False)
    covariance: tuple[float, ...] | None = param(
        "covariance of (v0_mm3, b, a), 9 numbers row by row (written by `matcad calibrate`)", "", None,
        kind="vector9", lo=-1e30, hi=1e30, lo_open=False)
    residual_std_mm3: float | None = param("standard deviation of the fit's residuals in K/f^2", "mm^3", None,
                                           lo=0.0, hi=1e30, lo_open=False)
    dof: int | None = param("degrees of freedom of the fit (points - 3)", default=None, kind="integer",
                            lo=1, hi=10**9)
    cycle_std_mm3: float | None = param(
        "between-cycle (hysteresis) standard deviation in K/f^2, estimated from several load cycles or assumed "
        "from the paper (written by `matcad calibrate`); added to every force interval", "mm^3", None,
        lo=0.0, hi=1e30, lo_open=False)
    temperature_c: float | None = param("air temperature during calibration; `sense --temperature-c` scales "
                                        "frequencies by sqrt(T/T_cal) (f follows c)", "degC", None,
                                        lo=-273.15, hi=1000.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        _check_calibration(self)


def _check_calibration(cal: Calibration) -> None:
    """What sensing needs of a calibration beyond each field's range: a covariance that is one (symmetric,
    variances >= 0, no negative eigenvalue beyond rounding), and V_eff = v0 - bF - aF^2 > 0 over its force range
    (else f = sqrt(K/V_eff) is not real there)."""
    if cal.covariance is not None:
        import numpy as np

        cov = np.array(cal.covariance, dtype=float).reshape(3, 3)
        scale = float(np.max(np.abs(cov))) or 1.0
        if np.any(np.diag(cov) < 0) or not np.allclose(cov, cov.T, rtol=1e-9, atol=1e-12 * scale) \
                or float(np.min(np.linalg.eigvalsh((cov + cov.T) / 2))) < -1e-9 * scale:
            raise SpecError("calibration.covariance", list(cal.covariance),
                            "must be a covariance matrix: symmetric, variances >= 0, positive semi-definite")
    if cal.force_range_n is not None:
        for force in cal.force_range_n:
            if not cal.v0_mm3 - cal.b * force - cal.a * force * force > 0:
                raise SpecError("calibration.force_range_n", list(cal.force_range_n),
                                f"must keep V_eff = v0 - bF - aF^2 > 0 mm^3 (at F = {force:g} N it is not)")
