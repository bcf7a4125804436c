"""A fipple tube's prediction: the air column's routes (closed form, transmission line, 1-D FEM; for a flanged or
unflanged mouth on request the axisymmetric exterior FEM), the cap's
wall (the MAT wall model as the closed end's compliance), the edge-tone window of the first two modes, and f(F)
from the cap mechanics (the MAT cap pressed by a plate: its cavity's volume sets the closed end). Frequencies Hz,
forces N, lengths mm. Sources: docs/tube.md.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from matcad.acoustics import edgetone
from matcad.acoustics import tube as air
from matcad.acoustics.wall import HYBRID_BAND, mode_near

FEM_ELEMENTS = 64
"""P2 elements of the 1-D FEM route: 1e-7 Hz from the line's root on the template (docs/tube.md)."""
MOUTH_SPREAD = 0.25
"""Assumed ± fraction on the fipple mouth's correction (Rayleigh's aperture conductance for a window in a curved
wall next to a jet; no measurement of it is at hand): a part of the band, named as an assumption. A second route
(potential flow through the printed window, benchmarks/fipple_window.py) puts the template's window at ~1.21 × it:
inside +25 %, the wall's depth left out by the model (docs/tube.md)."""


@dataclass(frozen=True)
class TubeLoad:
    """f at one force: F (N), the cap cavity's volume (mm³), the closed end's equivalent depth V/S (mm), f (Hz)."""

    force_n: float
    cavity_volume_mm3: float
    cap_depth_mm: float
    f_hz: float


@dataclass(frozen=True)
class TubePrediction:
    """The tube's unloaded f1 from each route (Hz), the chosen ``f0_hz`` and its ``band_hz``, the mouth correction
    and the cap's compliance length (mm), the overblown mode (Hz), the edge-tone windows, notes, f(F) points."""

    name: str
    column_mm: float
    mouth_correction_mm: float
    routes_hz: dict
    f0_hz: float
    band_hz: tuple[float, float]
    band_sources: tuple[str, ...]
    kappa_mm: float | None
    f_mode2_hz: float
    windows: tuple[edgetone.Window, ...]
    notes: tuple[str, ...]
    loads: tuple[TubeLoad, ...] = ()

    def to_dict(self) -> dict:
        return {"name": self.name, "kind": "tube", "column_mm": self.column_mm,
                "mouth_correction_mm": self.mouth_correction_mm, "routes_hz": self.routes_hz, "f0_hz": self.f0_hz,
                "band_hz": list(self.band_hz), "band_sources": list(self.band_sources), "kappa_mm": self.kappa_mm,
                "f_mode2_hz": self.f_mode2_hz, "edge_tone": [dataclasses.asdict(w) for w in self.windows],
                "notes": list(self.notes), "loads": [dataclasses.asdict(p) for p in self.loads]}

    def to_text(self) -> str:
        lines = [f"{self.name}: fipple tube, air column {self.column_mm:g} mm + mouth correction "
                 f"{self.mouth_correction_mm:.2f} mm"]
        width = max(map(len, self.routes_hz))
        lines += [f"  {route:<{width}} {f:8.0f} Hz" for route, f in self.routes_hz.items()]
        lines.append(f"  f1 = {self.f0_hz:.0f} Hz, band {self.band_hz[0]:.0f}-{self.band_hz[1]:.0f} Hz "
                     f"({'; '.join(self.band_sources)})")
        lines.append(f"  overblown mode: {self.f_mode2_hz:.0f} Hz")
        for w in self.windows:
            lines.append(f"  mode {w.mode} speaks for jet speeds {w.u_min_m_s:.0f}-{w.u_max_m_s:.0f} m/s (optimum "
                         f"{w.u_optimum_m_s:.0f} m/s = {w.flow_optimum_l_min:.2f} L/min through the windway, "
                         f"{w.pressure_optimum_pa:.0f} Pa)")
        lines += [f"  f({p.force_n:g} N) = {p.f_hz:.0f} Hz (cap cavity {p.cavity_volume_mm3:.1f} mm3, closed end "
                  f"{p.cap_depth_mm:.2f} mm deep)" for p in self.loads]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def _wall_results(td: air.TubeDesign):
    """f1 (Hz) and κ (mm) at the low, mid and high dynamic shear modulus; and the notes on cap modes near f1."""
    results, notes = [], []
    for g in td.wall.dynamic_moduli_pa():
        f, kappa = air.with_wall_hz(td, g)
        results.append((f, kappa))
        near = mode_near(air.cap_wall_modes(td, g), f)
        if near is not None:
            notes.append(f"a cap mode at {near:.0f} Hz lies within {HYBRID_BAND:.0%} of f1 = {f:.0f} Hz "
                         f"(G = {g / 1e6:.2g} MPa): two resonances may compete")
    return results, notes


def predict_tube(spec, forces_n=(), fem_level: int | None = None) -> TubePrediction:
    """The prediction of a ``kind = "tube"`` spec, with f at ``forces_n`` (N) from the cap mechanics (FElupe,
    imported only then); with ``fem_level`` (elements across the bore's radius) also the axisymmetric exterior
    FEM's f1 of a flanged or unflanged tube (scikit-fem, :func:`matcad.acoustics.tube.exterior_fem`; ValueError for
    a fipple mouth)."""
    td = air.tube_design(spec)
    routes = {"closed form (rigid)": air.closed_form_hz(td), "line (rigid)": air.line_hz(td),
              "1-D FEM P2 (rigid)": air.fem_hz(td, 0.0, FEM_ELEMENTS, 2)}
    if fem_level is not None:
        routes[f"exterior FEM, level {fem_level} (rigid)"] = air.exterior_fem(td, fem_level).f0_hz
    notes: list[str] = []
    f0, kappa, band = routes["line (rigid)"], None, [routes["line (rigid)"]] * 2
    sources = ["rigid cap"]
    if td.wall.model == "silicone":
        results, notes = _wall_results(td)
        routes["line + cap wall"] = results[1][0]
        routes["1-D FEM + cap wall"] = air.with_wall_hz(td, td.wall.dynamic_moduli_pa()[1], air.fem_hz)[0]
        f0, kappa = results[1]
        band = [min(f for f, _ in results), max(f for f, _ in results)]
        sources = ["cap shear modulus range"]
    if td.mouth == "fipple":
        k = kappa or 0.0
        for factor in (1 - MOUTH_SPREAD, 1 + MOUTH_SPREAD):
            shifted = f0 * air.line_hz(td, k, correction_factor=factor) / air.line_hz(td, k)
            band = [min(band[0], shifted), max(band[1], shifted)]
        sources.append(f"fipple mouth correction +-{MOUTH_SPREAD:.0%} (assumed)")
    f2 = air.line_hz(td, kappa or 0.0, mode=2)
    windows = tuple(edgetone.window(f, mode, td.edge_distance, td.windway_height, td.windway_width)
                    for mode, f in ((1, f0), (2, f2)))
    loads = _loads(spec, td, f0, forces_n) if forces_n else ()
    return TubePrediction(spec.name, td.column_mm, air.mouth_correction_mm(td), routes, f0, tuple(band),
                          tuple(sources), kappa, f2, windows, tuple(notes), loads)


def _loads(spec, td: air.TubeDesign, f0_hz: float, forces_n) -> tuple[TubeLoad, ...]:
    """f at each force: the cap pressed by a plate (the MAT cap mechanics on the tube's cap) shrinks its cavity to
    V(F); the closed end moves to V(F)/S, and f(F) = f0 × f_line(V(F)/S) / f_line(V(0)/S) (rigid line ratio, as
    the MAT f(F)). Forces beyond the curve's last converged step raise ValueError."""
    import numpy as np

    from matcad.mechanics.case import cap_case
    from matcad.prediction.curves import cap_curve

    curve = cap_curve(cap_case(spec))
    force, volume = curve.column("force_n"), curve.column("cavity_volume_mm3")
    rising = int(np.argmax(np.append(np.diff(force) <= 0, True)))  # the curve up to its first non-rising step
    force, volume = force[:rising + 1], volume[:rising + 1]
    base = air.line_hz(td)
    points = []
    for f_n in forces_n:
        if not force[0] <= f_n <= force[-1]:
            raise ValueError(f"--load {f_n:g} N is outside the cap's computed range 0-{force[-1]:.3g} N "
                             "(raise mechanics.displacement_mm)")
        v = float(np.interp(f_n, force, volume))
        depth = v / td.bore_area_mm2
        f = air.line_hz(dataclasses.replace(td, cap_depth=depth))
        points.append(TubeLoad(f_n, v, depth, f0_hz * f / base))
    return tuple(points)
