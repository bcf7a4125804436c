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
from matcad.acoustics.design import Air
from matcad.acoustics.uncertainty import CAVITY_DIAMETER_TOL_MM, TEMPERATURE_TOL_C
from matcad.acoustics.wall import HYBRID_BAND, mode_near

FEM_ELEMENTS = 64
"""P2 elements of the 1-D FEM route: 1e-7 Hz from the line's root on the template (docs/tube.md)."""
MOUTH_STUDY_BORE_MM = 4.0
MOUTH_STUDY = ((1.2, 3.5, 2.0, 20.0), (0.8, 3.5, 2.0, 20.0), (2.0, 3.5, 2.0, 20.0), (1.2, 2.5, 2.0, 20.0),
               (1.2, 3.5, 1.2, 20.0), (1.2, 3.5, 3.0, 20.0), (1.2, 3.5, 2.0, 10.0), (1.2, 3.5, 2.0, 30.0),
               (1.2, 2.0, 1.0, 20.0), (0.8, 3.9, 3.5, 15.0))
"""The ten windows :data:`MOUTH_RANGE` was measured on: (tube.wall, windway_width B, edge_distance W mm,
edge_angle deg) on a bore of :data:`MOUTH_STUDY_BORE_MM`; the template's own first."""
MOUTH_RANGE = (0.80, 1.45)
"""The fipple window's true δ over Rayleigh's thin aperture (the model's): measured by the 3-D potential-flow FEM
of the printed mouth (:func:`matcad.acoustics.tube.window_fem`, level 8) over ten windows, 0.84–1.32 (the wall's
depth lengthens δ, the labium's bevels and the curved wall shorten it). Level 8 is low: by 1.1 % against level 12
on the 1.32 window and level 12 by 1.8 % (the unflanged pipe against the axisymmetric FEM), 1.36 in all, kept at
1.45 for the windows not refined; on thin walls by 6–10 % (0.8 mm walls: their 0.89 and 0.84 rise to 0.95 and
0.93, away from the bottom). benchmarks/fipple_window.py, docs/tube.md. A part of the band."""
TRANSVERSE_STUDY = ((1.2, 3.5, 2.0, 0.5), (0.8, 3.5, 2.0, 0.5), (2.0, 3.5, 2.0, 0.5), (1.2, 2.5, 2.0, 0.5),
                    (1.2, 5.0, 2.0, 0.5), (1.2, 3.5, 1.2, 0.5), (1.2, 3.5, 3.0, 0.5), (1.2, 3.5, 2.0, 1.0))
"""The windows :data:`TRANSVERSE_RANGE` was measured on: (tube.wall, windway_width B, edge_distance W,
windway_height h mm) on a bore of :data:`MOUTH_STUDY_BORE_MM`; the template's own first."""
TRANSVERSE_RANGE = (0.85, 1.70)
"""A transverse window's δ over Rayleigh's aperture of its area, by the 3-D FEM (level 8) over
:data:`TRANSVERSE_STUDY`: 0.89 (W 3 mm, a window across most of the bore's side) to 1.52 (a 2 mm wall). Level 8
is low: the template's 1.188 is 1.215 at level 10 and 1.226 at level 12, still rising (~4 % in all); the top
widened by 6 % and rounded up, the bottom kept below the lowest. docs/tube.md. A part of the band."""

JET_RANGE = (0.93, 1.0)
"""The sounding pitch over the air column's resonance (f0): a jet-driven pipe sounds below its resonance when blown
softly, up to it when blown hard (the jet's delay across the mouth sets the loop's phase: Fletcher & Rossing 1998
§16.3, §17.3). Measured on four fipple whistles with every hole closed, their softest to hardest speaking pitch
(WWIDesigner v2.6.0's tunings, github.com/edwardkort/WWIDesigner: Feadog Mk 1 560-600 Hz, BP7 568-589, BP8
568-585, a sample PVC whistle 560-589; fmin/fmax 0.933-0.971), the hardest taken as the resonance there
(its ``PlayingRange``: fmax where Im Z = 0). A part of the band (docs/tube.md)."""


@dataclass(frozen=True)
class WindowStudy:
    """Where a window's δ over Rayleigh's was measured by the 3-D FEM: the design's fields per window (the
    :class:`matcad.acoustics.tube.TubeDesign` attribute and the spec's field; lengths on a bore of
    :data:`MOUTH_STUDY_BORE_MM`, angles in deg), the windows, the ratio's range the band carries, its source."""

    fields: tuple[tuple[str, str], ...]
    windows: tuple[tuple[float, ...], ...]
    ratio: tuple[float, float]
    source: str


WINDOW_STUDIES = {
    "fipple": WindowStudy((("tube_wall", "tube.wall"), ("windway_width", "tube.windway_width"),
                           ("edge_distance", "tube.edge_distance"), ("edge_angle", "tube.edge_angle")),
                          MOUTH_STUDY, MOUTH_RANGE, "3-D FEM over ten windows"),
    "transverse": WindowStudy((("tube_wall", "tube.wall"), ("windway_width", "tube.windway_width"),
                               ("edge_distance", "tube.edge_distance"), ("windway_height", "tube.windway_height")),
                              TRANSVERSE_STUDY, TRANSVERSE_RANGE, "3-D FEM over eight transverse windows"),
}
"""Per windowed mouth (:data:`matcad.spec.tube.WINDOWED`), its :class:`WindowStudy`."""


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
    and the cap's compliance length (mm), the overblown mode (Hz), the edge-tone windows, notes, f(F) points; its
    ``mouth`` (:data:`matcad.spec.tube.MOUTHS`)."""

    name: str
    mouth: str
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
        return {"name": self.name, "kind": "tube", "mouth": self.mouth, "column_mm": self.column_mm,
                "mouth_correction_mm": self.mouth_correction_mm, "routes_hz": self.routes_hz, "f0_hz": self.f0_hz,
                "band_hz": list(self.band_hz), "band_sources": list(self.band_sources), "kappa_mm": self.kappa_mm,
                "f_mode2_hz": self.f_mode2_hz, "edge_tone": [dataclasses.asdict(w) for w in self.windows],
                "notes": list(self.notes), "loads": [dataclasses.asdict(p) for p in self.loads]}

    def to_text(self) -> str:
        lines = [f"{self.name}: tube with a {self.mouth} mouth, air column {self.column_mm:g} mm + mouth correction "
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


def _made(td: air.TubeDesign, printer: str) -> tuple[air.TubeDesign, ...]:
    """The design as it may be made and run: the printed bore ± the printer's tolerance on a printed core
    (:data:`matcad.acoustics.uncertainty.CAVITY_DIAMETER_TOL_MM`, as the MAT cavity's), the air ±
    :data:`matcad.acoustics.uncertainty.TEMPERATURE_TOL_C` (unless its speed of sound is given: exact)."""
    tol = CAVITY_DIAMETER_TOL_MM[printer]
    out = [dataclasses.replace(td, bore_diameter=td.bore_diameter + s * tol) for s in (-1, 1)]
    if td.air.speed_of_sound_m_s is None:
        out += [dataclasses.replace(td, air=Air(td.air.temperature_c + s * TEMPERATURE_TOL_C)) for s in (-1, 1)]
    return tuple(out)


def _outside_mouth_study(td: air.TubeDesign, study: WindowStudy) -> list[str]:
    """A note for each of the window's proportions (per bore radius; an angle in deg) outside those of ``study``'s
    windows, where its ratio's range is not measured."""
    a, a_study = td.bore_diameter / 2, MOUTH_STUDY_BORE_MM / 2
    notes = []
    for column, (attribute, field) in enumerate(study.fields):
        angle = attribute.endswith("angle")
        value, unit = (getattr(td, attribute), 1.0) if angle else (getattr(td, attribute) / a, a)
        scale = 1.0 if angle else a_study
        lo, hi = (f(w[column] / scale for w in study.windows) for f in (min, max))
        if not lo - 1e-9 <= value <= hi + 1e-9:
            notes.append(f"{field} = {value * unit:g} lies outside the windows the mouth's range was measured on "
                         f"({lo * unit:g}-{hi * unit:g} for this bore): the band may not hold the window's "
                         "correction; `predict --model fem` solves it")
    return notes


def predict_tube(spec, forces_n=(), fem_level: int | None = None) -> TubePrediction:
    """The prediction of a ``kind = "tube"`` spec, with f at ``forces_n`` (N) from the cap mechanics (FElupe,
    imported only then); with ``fem_level`` (elements across the bore's radius) also the FEM rung (scikit-fem): the
    axisymmetric exterior FEM's f1 of a flanged or unflanged tube (:func:`matcad.acoustics.tube.exterior_fem`), the
    line with the 3-D FEM's δ of a fipple or transverse window (:func:`matcad.acoustics.tube.window_fem`, ~20-30 s
    at level 8)."""
    td = air.tube_design(spec)
    routes = {"closed form (rigid)": air.closed_form_hz(td), "line (rigid)": air.line_hz(td),
              "1-D FEM P2 (rigid)": air.fem_hz(td, 0.0, FEM_ELEMENTS, 2)}
    if fem_level is not None and td.mouth in WINDOW_STUDIES:
        routes[f"3-D window FEM + line, level {fem_level} (rigid)"] = air.window_fem(td, fem_level)[1]
    elif fem_level is not None:
        routes[f"exterior FEM, level {fem_level} (rigid)"] = air.boundary_layer_hz(td, air.exterior_fem(td, fem_level)
                                                                                   .f0_hz)
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
    k = kappa or 0.0
    base = air.line_hz(td, k)  # each uncertainty below moves f0 by the rigid-cap line's ratio
    shifted = [JET_RANGE[0] * f0, JET_RANGE[1] * f0]
    if td.mouth in WINDOW_STUDIES:
        study = WINDOW_STUDIES[td.mouth]
        shifted += [f0 * air.line_hz(td, k, correction_factor=factor) / base for factor in study.ratio]
        sources.append(f"{td.mouth} mouth correction x{study.ratio[0]:g}-{study.ratio[1]:g} ({study.source})")
        notes += _outside_mouth_study(td, study)
    shifted += [f0 * air.line_hz(made, k) / base for made in _made(td, spec.machine.printer)]
    temperature = "" if td.air.speed_of_sound_m_s is not None else f", air +-{TEMPERATURE_TOL_C:g} C"
    sources.append(f"printed bore +-{CAVITY_DIAMETER_TOL_MM[spec.machine.printer]:g} mm "
                   f"({spec.machine.printer}){temperature}")
    sources.append(f"the jet: sounding x{JET_RANGE[0]:g}-{JET_RANGE[1]:g} of the resonance (four measured whistles)")
    band = [min(band[0], *shifted), max(band[1], *shifted)]
    f2 = air.line_hz(td, k, mode=2)
    windows = tuple(edgetone.window(f, mode, td.edge_distance, td.windway_height, td.windway_width)
                    for mode, f in ((1, f0), (2, f2)))
    loads = _loads(spec, td, f0, forces_n) if forces_n else ()
    return TubePrediction(spec.name, td.mouth, td.column_mm, air.mouth_correction_mm(td), routes, f0, tuple(band),
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
