"""A tube's report beside a MAT taxel at the same pitch and over the same forces: length, air volume, f(F)
sensitivity, fabrication steps (docs/tube.md). Lengths mm, volumes mm³, frequencies Hz, forces N.

The MAT taxel is the paper's (the shipped mat-paper template) with ``neck.diameter`` solved onto the tube's f1
(:func:`matcad.design.solve.solve`, the model ``predict`` chooses): its cavity and cap stay the paper's, so its f(F)
is the paper cap's. f(F) of both from the cap mechanics (FElupe; the curves are cached).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

FORCES_N = (0.0, 1.0, 3.0)
MAT_TEMPLATE = "mat-paper"
VARIED = "neck.diameter"


@dataclass(frozen=True)
class Comparison:
    """The MAT taxel and the tube side by side (mm, mm³, Hz at ``FORCES_N``); ``unavailable`` says why no MAT taxel
    was compared (then the numbers are empty)."""

    unavailable: str = ""
    mat_f_hz: tuple[float, ...] = ()
    tube_f_hz: tuple[float, ...] = ()
    mat_neck_mm: tuple[float, float] = (0.0, 0.0)
    mat_cavity_mm: tuple[float, float] = (0.0, 0.0)
    tube_column_mm: tuple[float, float] = (0.0, 0.0)
    mat_length_mm: float = 0.0
    tube_length_mm: float = 0.0
    mat_air_mm3: tuple[float, float] = (0.0, 0.0)
    tube_air_mm3: float = 0.0
    mat_steps: tuple[str, ...] = ()
    tube_steps: int = 0

    def to_dict(self) -> dict:
        return dataclasses.asdict(self) | {"forces_n": list(FORCES_N),
                                           "mat": f"{MAT_TEMPLATE} with {VARIED} solved onto the tube's f1"}

    def to_markdown(self) -> list[str]:
        head = [f"A MAT taxel at the same pitch: the paper's ({MAT_TEMPLATE}) with {VARIED} solved onto the tube's "
                "f1; f(F) of both from the cap mechanics.", ""]
        if self.unavailable:
            return head + [f"Not compared: {self.unavailable}"]
        (d, l), (dc, lc), (bore, column) = self.mat_neck_mm, self.mat_cavity_mm, self.tube_column_mm
        rows = (("pitch f1 (Hz)", f"{self.mat_f_hz[0]:.0f} ({VARIED} {d:.3f} mm)", f"{self.tube_f_hz[0]:.0f}"),
                ("resonator (mm)", f"cavity Ø{dc:g} × {lc:g}, neck Ø{d:.2f} × {l:g}", f"column Ø{bore:g} × {column:g}"),
                ("taxel length (mm)", f"{self.mat_length_mm:.2f} (spacer + plate + cap)",
                 f"{self.tube_length_mm:.2f} (foot + window + bore + cap)"),
                ("air volume (mm³)", f"{sum(self.mat_air_mm3):.1f} (cavity {self.mat_air_mm3[0]:.1f} + neck "
                 f"{self.mat_air_mm3[1]:.1f})", f"{self.tube_air_mm3:.1f} (column)"),
                ("f(F) − f(0)", _shifts(self.mat_f_hz), _shifts(self.tube_f_hz)),
                ("fabrication steps", f"{len(self.mat_steps)} ({'; '.join(self.mat_steps)})",
                 f"{self.tube_steps} (print the tube; print the mold and cast the cap; glue; needle)"))
        return head + ["| | MAT taxel | fipple tube |", "|---|---|---|"] + [f"| {a} | {b} | {c} |" for a, b, c in rows]


def _shifts(points) -> str:
    return ", ".join(f"{f - points[0]:+.1f} Hz at {force:g} N" for force, f in zip(FORCES_N[1:], points[1:]))


def compare(tube_spec, tube_f0_hz: float, tube_steps) -> Comparison:
    """The comparison for a ``kind = "tube"`` spec singing at ``tube_f0_hz`` (Hz), made in ``tube_steps`` (its
    kit's steps); a MAT taxel the solver cannot reach or the rules refuse, or a force beyond a cap's computed
    range, gives ``unavailable`` with the reason."""
    from matcad.design import RulesFailed, Unreachable
    from matcad.design.solve import solve
    from matcad.init import template_path
    from matcad.parts.tube import heights_mm
    from matcad.prediction import predict
    from matcad.prediction.tube import predict_tube
    from matcad.report.fabrication import steps
    from matcad.spec import cap_height_mm, load

    try:
        mat = solve(load(template_path(MAT_TEMPLATE)), tube_f0_hz, {VARIED: None}).spec
        p_mat = predict(mat, forces_n=FORCES_N)
        f_mat = tuple(p.f_hz for p in p_mat.load_curve if p.source.startswith("cap mechanics"))
        f_tube = tuple(p.f_hz for p in predict_tube(tube_spec, FORCES_N).loads)
    except (Unreachable, RulesFailed, ValueError) as err:
        return Comparison(unavailable=str(err))
    t, c, n = tube_spec.tube, mat.cavity, mat.neck
    column = t.length + t.cap_cavity_depth
    return Comparison(
        mat_f_hz=f_mat, tube_f_hz=f_tube, mat_neck_mm=(n.diameter, n.length), mat_cavity_mm=(c.diameter, c.length),
        tube_column_mm=(t.bore_diameter, column), mat_length_mm=mat.spacer.height + n.length + cap_height_mm(mat),
        tube_length_mm=heights_mm(tube_spec)["top"] + cap_height_mm(tube_spec),
        mat_air_mm3=(math.pi * c.diameter**2 / 4 * c.length, math.pi * n.diameter**2 / 4 * n.length),
        tube_air_mm3=math.pi * t.bore_diameter**2 / 4 * column, mat_steps=tuple(s["where"] for s in steps(mat, [])),
        tube_steps=len(tube_steps))
