"""What the air sees of one taxel as it will be built: the typed inputs of the acoustic floor, and the adapter that
builds them from a validated spec. Lengths mm, speeds m/s, moduli MPa (static) or Pa (where a name says so),
densities kg/m³, temperatures °C.

Every acoustic computation (the model ladder, the uncertainty budget, the FEM rungs) takes a :class:`Design`, never
the whole spec. Its numeric fields may be numpy arrays of equal length: a sweep then evaluates the same models on
every variant at once (:mod:`matcad.sweep.fast`). :func:`design` is the one adapter from a spec (and one of its
taxels) to a Design; :func:`reference` and :func:`calibration` adapt the spec's [reference] and [calibration].
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Air:
    """The air in the taxel: its temperature (°C) and, when given, its speed of sound (m/s; None: from the
    temperature). An array design marks "not given" with NaN."""

    temperature_c: float
    speed_of_sound_m_s: float | None = None


@dataclass(frozen=True)
class WallMaterial:
    """The cavity wall as the acoustics sees it: ``model`` 'rigid' or 'silicone'; the silicone's static shear modulus
    range (MPa), its storage modulus at kHz over the static one (range), its loss factor range and its density
    (kg/m³)."""

    model: str
    shear_modulus_mpa: tuple[float, float]
    khz_modulus_factor: tuple[float, float]
    loss_factor: tuple[float, float]
    density_kg_m3: float

    def static_moduli_pa(self) -> tuple[float, float, float]:
        """(low, geometric mean, high) of the static shear-modulus range (Pa)."""
        g_lo, g_hi = (x * 1e6 for x in self.shear_modulus_mpa)
        return g_lo, float(np.sqrt(g_lo * g_hi)), g_hi

    def dynamic_moduli_pa(self) -> tuple[float, float, float]:
        """(low, geometric mean, high) storage shear modulus at kHz (Pa): the static range times the kHz factor."""
        f_lo, f_hi = self.khz_modulus_factor
        g_lo, _, g_hi = self.static_moduli_pa()
        lo, hi = g_lo * f_lo, g_hi * f_hi
        return lo, float(np.sqrt(lo * hi)), hi

    def loss_factors(self) -> tuple[float, float, float]:
        """(low, mean, high) of the loss-factor range."""
        lo, hi = self.loss_factor
        return lo, 0.5 * (lo + hi), hi


@dataclass(frozen=True)
class Making:
    """How the taxel is made, which sets the fabrication tolerances of the budget: the neck drilled to size from a
    pilot (else laser cut), the neck sheet calipered (else nominal cast sheet), the printer of the core pin ('fdm'
    or 'sla'), and the riser sheet the neck runs on through (its thickness in mm, 0 for none; calipered or not).
    An array design may make each variant its own way (arrays of those values)."""

    neck_drilled: bool
    sheet_measured: bool
    printer: str
    riser_mm: float = 0.0
    riser_measured: bool = False


@dataclass(frozen=True)
class Design:
    """One taxel as built, for the acoustics (mm): the cavity (diameter D at the plate, length L, core-pin draft in
    degrees), the neck (diameter d, length l = the plate's sheet, and a riser's where it runs on through one) and
    its outer end (``mouth``: 'baffled', 'unflanged' or 'mount', with the mount's gap height and vent radius), the
    silicone cap around the cavity (outer diameter, top thickness, height clamped by the guide and, for a cap in a
    riser's pocket, the riser), the air, the wall material and how it is made.

    As-built deviations the drawing does not show (docs/inference.md): ``neck_taper_mm``, the neck's diameter at
    the mouth minus at the cavity (a laser's taper; ``neck_diameter`` is their mean), and ``side_volume_mm3``, air
    joined to the cavity at the plate (gaps in the stack, a counterbore) that the cavity's walls do not hold."""

    cavity_diameter: float
    cavity_length: float
    draft_deg: float
    neck_diameter: float
    neck_length: float
    mouth: str
    gap_mm: float
    gap_radius_mm: float
    cap_outer_diameter: float
    cap_top_thickness: float
    cap_clamp_height: float
    air: Air
    wall: WallMaterial
    making: Making
    neck_taper_mm: float = 0.0
    side_volume_mm3: float = 0.0

    def replace(self, **values) -> Design:
        """A copy with fields set (``air_temperature_c`` sets the air's temperature): a model variant, unvalidated,
        as the budget and sweeps perturb it."""
        air = values.pop("air_temperature_c", None)
        if air is not None:
            values["air"] = dataclasses.replace(self.air, temperature_c=air)
        return dataclasses.replace(self, **values)


def _air(spec) -> Air:
    """The spec's [air] as the models read it."""
    return Air(spec.air.temperature_c, spec.air.speed_of_sound)


def design(spec, taxel=None) -> Design:
    """The :class:`Design` of ``spec``'s taxel ``taxel`` (a :class:`matcad.spec.board.Taxel`; default: the spec's
    own tables, i.e. a single-taxel spec). The mouth's gap is the spacer height and its vent radius half the plate's
    smaller side; the cap is clamped over the flange's thickness (guide sheet + squeeze, + the riser's for a cap in
    a riser's pocket); the neck runs through the plate's sheet, and the riser's where it runs on through one."""
    from matcad.spec import cap_flange_thickness_mm, neck_length_mm

    cavity, neck, cap = (spec.cavity, spec.neck, spec.end_cap) if taxel is None else \
        (taxel.cavity, taxel.neck, taxel.end_cap)
    wall = spec.wall
    length = neck_length_mm(spec, taxel)
    riser = spec.riser if length != neck.length else None
    return Design(
        cavity_diameter=cavity.diameter, cavity_length=cavity.length, draft_deg=spec.mold.draft_deg,
        neck_diameter=neck.diameter, neck_length=length, mouth=neck.mouth, gap_mm=spec.spacer.height,
        gap_radius_mm=float(gap_radius_mm(spec.plate.width, spec.plate.depth)), cap_outer_diameter=cap.outer_diameter,
        cap_top_thickness=cap.top_thickness, cap_clamp_height=cap_flange_thickness_mm(spec, taxel),
        air=_air(spec),
        wall=WallMaterial(wall.model, wall.shear_modulus_mpa, wall.khz_modulus_factor, wall.loss_factor,
                          spec.silicone.density_g_cm3 * 1000.0),
        making=Making(spec.plate.neck_pilot, spec.plate.thickness_measured, spec.machine.printer,
                      riser.thickness if riser else 0.0, bool(riser and riser.thickness_measured)))


@dataclass(frozen=True)
class Reference:
    """A taxel that was built and recorded: its design and its measured unloaded f0 ± tolerance (Hz)."""

    design: Design
    f0_hz: float
    f0_tolerance_hz: float


def reference(spec) -> Reference | None:
    """The spec's [reference] taxel: this design with the reference's geometry, and its measurement; None without."""
    if spec.reference is None:
        return None
    from matcad.spec import reference_spec

    return Reference(design(reference_spec(spec)), spec.reference.f0_hz, spec.reference.f0_tolerance_hz)


def eq5(cal):
    """A spec's [calibration] table (or a calibration file's) as an :class:`~matcad.acoustics.eq5.Eq5`, the paper's
    own constants named as such; not yet tied to a neck unless the table carries its K."""
    from matcad.acoustics.eq5 import MAT_PAPER_2024, Eq5

    paper = MAT_PAPER_2024
    if (cal.v0_mm3, cal.a, cal.b, cal.area_convention) == (paper.v0_mm3, paper.a, paper.b, paper.area_convention) \
            and cal.k_mm3_hz2 is None:
        return paper
    return Eq5(cal.v0_mm3, cal.a, cal.b, cal.k_mm3_hz2, cal.area_convention, "spec", cal.covariance,
               cal.residual_std_mm3, cal.dof, cal.force_range_n, cal.cycle_std_mm3 or 0.0, cal.temperature_c)


def calibration(spec, d: Design | None = None):
    """The single-taxel ``spec``'s [calibration] (a board's taxel through :func:`matcad.spec.taxel_spec` carries its
    own [taxel.calibration]) as an :class:`~matcad.acoustics.eq5.Eq5` tied to its neck and air (``d``: its design,
    when the caller has it); None without one."""
    if spec.calibration is None:
        return None
    if d is None:  # the neck and the air only: what Eq. 5's K reads (a sweep memoises on the fields read)
        from matcad.spec import neck_length_mm

        air, diameter, length = _air(spec), spec.neck.diameter, neck_length_mm(spec)
    else:
        air, diameter, length = d.air, d.neck_diameter, d.neck_length
    return eq5(spec.calibration).bound(speed_of_sound(air), diameter, length)


def speed_of_sound(air: Air):
    """The air's speed of sound (m/s): the given one, else from its temperature (°C); arrays of variants too
    (NaN: not given)."""
    from matcad.acoustics.air import speed_of_sound_m_s

    given = air.speed_of_sound_m_s
    if np.ndim(air.temperature_c) == 0 and np.ndim(given) == 0:
        return float(given or speed_of_sound_m_s(air.temperature_c))
    given = np.asarray(np.nan if given is None else given, dtype=float)
    return np.where(np.isnan(given), speed_of_sound_m_s(air.temperature_c), given)


def gap_radius_mm(plate_width_mm, plate_depth_mm):
    """Radius out to which the mount's gap vents (mm): half the neck plate's smaller side (the plate's edges)."""
    return np.minimum(plate_width_mm, plate_depth_mm) / 2.0
