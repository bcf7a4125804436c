"""Plausibility notes: values that validate but are probably a unit slip, each with the value it probably meant.

Validation (:mod:`matcad.spec`) refuses what is not physical; these notes catch what is physical but unlikely
for a milli-scale taxel: a shear modulus entered in kPa, a temperature in kelvin, an angle in radians, a spec
in metres or inches, a sample rate in kHz, a calibration CSV in kHz. A note suggests a value only when that value is
plausible itself (inside the field's range and drawing no note of its own); else it says what is implausible. They
never change a value; the CLI prints them and the design page shows them with the prediction.
"""

from __future__ import annotations

import math

from matcad.listening import FREQUENCY_KHZ_MAX  # kHz-slip threshold, with the listening band (`analyze --band`)
from matcad.spec.sections import WALL_SHEAR_MIN_MPA

SILICONE_G_MAX_MPA = 50.0
"""Cast silicones are 0.05-5 MPa in shear; above 50 MPa the value was almost surely typed in kPa."""
AIR_TEMPERATURE_MAX_C = 150.0
"""A taxel in air hotter than 150 °C is unlikely; 250-400 reads as kelvin."""
THETA_RADIANS_MAX = math.pi / 2
"""A needle angle ≤ π/2 "degrees" is more likely radians (the paper's 75° is 1.31 rad)."""
METRES_MAX = 0.05
"""Every main dimension below 0.05 "mm" reads as a spec written in metres."""
INCHES_MAX = 1.0
"""Every main dimension below 1 "mm" (and not metres) reads as a spec in inches: the paper's taxel is inch
fractions (cavity 1/8 x 3/16 in, neck sheet 1/4 in), and a taxel under 1 mm would sing far above the microphone's
band (the paper's in "mm": f0 ~ 142 kHz)."""
MM_PER_INCH = 25.4
SAMPLE_RATE_KHZ_MAX = 400.0
FREQUENCY_KHZ_MIN = FREQUENCY_KHZ_MAX / 1000
"""...unless even in kHz they would lie below FREQUENCY_KHZ_MAX Hz: then no unit slip explains them, and no note."""


def _slip(told: str, unit: str, meant: str, plausible: bool, implausible: str) -> str:
    """A unit-slip note: ``told`` (the value and why it is unlikely), then whether ``unit`` was entered, suggesting
    ``meant`` (the value in that reading) only when it is ``plausible``; else saying that it is ``implausible``
    as well."""
    if plausible:
        return f"{told}: {unit} entered? did you mean {meant}?"
    return f"{told}; read as {unit} it would be {meant}, {implausible} as well: check the value"


def spec_notes(spec, data: dict | None = None) -> list[str]:
    """Likely unit slips in the validated ``spec`` and, given its raw TOML ``data``, defaults worth knowing."""
    notes = []
    g_lo, g_hi = spec.wall.shear_modulus_mpa
    if spec.wall.model == "silicone" and g_hi > SILICONE_G_MAX_MPA:
        lo, hi = g_lo / 1000, g_hi / 1000
        notes.append(_slip(f"wall.shear_modulus_mpa = [{g_lo:g}, {g_hi:g}] MPa is stiffer than acrylic; cast silicone "
                           "is 0.05-5 MPa", "kPa", f"[{lo:g}, {hi:g}] MPa",
                           WALL_SHEAR_MIN_MPA <= lo and hi <= SILICONE_G_MAX_MPA,
                           f"outside {WALL_SHEAR_MIN_MPA:g}-{SILICONE_G_MAX_MPA:g} MPa"))
    t = spec.air.temperature_c
    if t > AIR_TEMPERATURE_MAX_C:
        notes.append(_slip(f"air.temperature_c = {t:g} °C is hotter than a taxel's air (above "
                           f"{AIR_TEMPERATURE_MAX_C:g} °C)", "kelvin", f"{t - 273.15:.4g} °C",
                           t - 273.15 <= AIR_TEMPERATURE_MAX_C, f"above {AIR_TEMPERATURE_MAX_C:g} °C"))
    theta = spec.needle.theta_deg
    if 0 < theta <= THETA_RADIANS_MAX:
        notes.append(_slip(f"needle.theta_deg = {theta:g}° lays the needle almost flat on the plate (the paper's is "
                           "75°)", "radians", f"{math.degrees(theta):.4g}°", math.degrees(theta) > THETA_RADIANS_MAX,
                           "almost flat"))
    dims = {"cavity.diameter": spec.cavity.diameter, "cavity.length": spec.cavity.length,
            "neck.diameter": spec.neck.diameter, "neck.length": spec.neck.length} if spec.kind == "mat" else \
        {"tube.bore_diameter": spec.tube.bore_diameter, "tube.length": spec.tube.length}
    if all(v < METRES_MAX for v in dims.values()):
        meant = ", ".join(f"{k} = {v * 1000:g}" for k, v in dims.items())
        notes.append(f"every main dimension is below {METRES_MAX:g} mm: a spec in metres? lengths are mm; did you "
                     f"mean {meant}?")
    elif all(v < INCHES_MAX for v in dims.values()):
        meant = ", ".join(f"{k} = {v * MM_PER_INCH:.4g}" for k, v in dims.items())
        notes.append(f"every main dimension is below {INCHES_MAX:g} mm: a spec in inches? lengths are mm (1 in = "
                     f"{MM_PER_INCH:g} mm); did you mean {meant}?")
    rate = spec.microphone.sample_rate_hz
    if rate < SAMPLE_RATE_KHZ_MAX:
        notes.append(_slip(f"microphone.sample_rate_hz = {rate:g} Hz is below {SAMPLE_RATE_KHZ_MAX:g} Hz (sound cards "
                           "sample at 8-192 kHz)", "kHz",
                           f"{rate * 1000:g} Hz", rate * 1000 >= SAMPLE_RATE_KHZ_MAX,
                           f"below {SAMPLE_RATE_KHZ_MAX:g} Hz"))
    if data is not None and "wall" not in data:
        notes.append("no [wall] table: the walls default to rigid (wall.model = 'rigid'); a cast silicone cap has "
                     "wall modes near the tone that move it — set [wall] model = 'silicone' to include them")
    return notes


def frequency_notes(frequencies_hz, what: str = "frequency_hz") -> list[str]:
    """A note when every frequency is below :data:`FREQUENCY_KHZ_MAX` Hz (a column in kHz, probably), unless the
    largest is below :data:`FREQUENCY_KHZ_MIN` (no unit slip explains that)."""
    values = [float(f) for f in frequencies_hz]
    if values and FREQUENCY_KHZ_MIN <= max(values) < FREQUENCY_KHZ_MAX:
        return [f"{what}: every value is below {FREQUENCY_KHZ_MAX:g} Hz (max {max(values):g}): kHz entered? did you "
                f"mean {max(values) * 1000:g} Hz for the largest?"]
    return []
