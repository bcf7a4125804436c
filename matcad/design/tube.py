"""`matcad design --target-hz` for a ``kind = "tube"`` spec: the bore length that sings at a target f1, the rest of
the tube as given. Lengths mm, frequencies Hz. docs/tube.md.

The solved quantity is :attr:`matcad.prediction.tube.TubePrediction.f0_hz` (the transmission line with the cap's
wall at the mid modulus, or the rigid line for a rigid wall); f1 falls monotonically with the length, so a bracketed
root (Brent) on [LENGTH_RANGE_MM] is the design. The solved spec is then predicted and checked in full.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from matcad.acoustics import tube as air

LENGTH_RANGE_MM = (2.0, 1000.0)
"""tube.length's allowed range (matcad.spec.tube)."""
TOLERANCE_HZ = 1e-3


@dataclass(frozen=True)
class TubeSolution:
    """The solved spec, the target and the predicted f1 (Hz), the length found (mm) and the spec's findings."""

    spec: object
    target_hz: float
    f0_hz: float
    band_hz: tuple[float, float]
    length_mm: float
    findings: tuple

    def to_dict(self) -> dict:
        return {"kind": "tube", "target_hz": self.target_hz, "f0_hz": self.f0_hz, "band_hz": list(self.band_hz),
                "varied": {"tube.length": self.length_mm}, "findings": [f.to_dict() for f in self.findings]}

    def to_text(self) -> str:
        return (f"{self.spec.name}: tube.length = {self.length_mm:.3f} mm sings at {self.f0_hz:.1f} Hz (target "
                f"{self.target_hz:g} Hz; band {self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} Hz)")


def _f1_hz(td: air.TubeDesign) -> float:
    if td.wall.model != "silicone":
        return air.line_hz(td)
    return air.with_wall_hz(td, td.wall.dynamic_moduli_pa()[1])[0]


def solve_tube(spec, target_hz: float, name: str) -> TubeSolution:
    """The tube spec with ``tube.length`` solved so that f1 = ``target_hz`` (Hz), named ``name``. Raises ValueError
    when the target lies outside what the allowed lengths reach, RulesFailed when the solved tube breaks a rule
    at level error (e.g. its supply jet leaves the new pitch's edge-tone window)."""
    from scipy.optimize import brentq

    from matcad.prediction.tube import predict_tube
    from matcad.rules import check
    from matcad.spec import from_dict, to_dict

    td = air.tube_design(spec)
    lo, hi = LENGTH_RANGE_MM
    f_short, f_long = (_f1_hz(dataclasses.replace(td, length=x)) for x in (lo, hi))
    if not f_long <= target_hz <= f_short:
        raise ValueError(f"--target-hz {target_hz:g}: a tube of this bore, mouth and cap sings at {f_long:.0f}-"
                         f"{f_short:.0f} Hz over tube.length {lo:g}-{hi:g} mm; change tube.bore_diameter or the mouth")
    hybrid = (f"--target-hz {target_hz:g}: near this pitch a cap mode competes with the tube's (f1 jumps between two "
              "resonances as the length changes); change the cap (end_cap.top_thickness, silicone.grade) or the pitch")
    try:
        length = brentq(lambda x: _f1_hz(dataclasses.replace(td, length=x)) - target_hz, lo, hi, xtol=1e-9,
                        rtol=1e-12)
    except ValueError:
        raise ValueError(hybrid) from None
    data = to_dict(spec)
    data["name"] = name
    data["tube"]["length"] = round(length, 6)
    solved = from_dict(data)
    p = predict_tube(solved)
    if abs(p.f0_hz - target_hz) > TOLERANCE_HZ:  # Brent stopped on a jump of f1, not on a root
        raise ValueError(hybrid)
    findings = tuple(check(solved, p))
    if any(f.level == "error" for f in findings):
        from matcad.design import RulesFailed

        raise RulesFailed(f"tube.length = {length:.3f} mm sings at {target_hz:g} Hz but breaks a design rule",
                          findings)
    return TubeSolution(solved, target_hz, p.f0_hz, p.band_hz, length, findings)
