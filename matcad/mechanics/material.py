"""Hyperelastic presets for the cap: neo-Hookean, Yeoh, one-term Ogden, from the grade registry
(:mod:`matcad.materials`), scaled to a chosen initial shear modulus. Moduli MPa.

All three are written for the isochoric part only; the volumetric part is U(J) = K/2 (J − 1)² with
K = ``BULK_PER_SHEAR`` · G (Poisson's ratio 0.4995, a nearly incompressible silicone), added by the solver's
u–p–J formulation.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from matcad.materials import grade as grade_record

MODELS = ("neo_hookean", "yeoh", "ogden")
BULK_PER_SHEAR = 1000.0
"""K/G = 1000 ↔ ν = 0.4995: silicones sit at K ≈ 1 GPa, G ≈ 0.3 MPa (K/G ~ 3000); 1000 keeps J within 1e-3 of 1
at the cap's stresses while the Newton iterations stay well conditioned."""


@dataclass(frozen=True)
class Hyperelastic:
    """One hyperelastic law: ``model`` in :data:`MODELS`, its constants (MPa; Ogden α dimensionless), the
    initial shear modulus ``shear_modulus_mpa``, a note on where the constants come from and K/G."""

    model: str
    constants: tuple[float, ...]
    shear_modulus_mpa: float
    note: str
    bulk_per_shear: float = BULK_PER_SHEAR

    @property
    def bulk_modulus_mpa(self) -> float:
        return self.bulk_per_shear * self.shear_modulus_mpa

    def scaled(self, factor: float) -> Hyperelastic:
        """The same law ``factor`` times as stiff: every modulus constant (not Ogden's exponent) times ``factor``."""
        constants = (self.constants[0] * factor, self.constants[1]) if self.model == "ogden" else \
            tuple(c * factor for c in self.constants)
        return dataclasses.replace(self, constants=constants, shear_modulus_mpa=self.shear_modulus_mpa * factor,
                                   note=f"{self.note}; x {factor:.4g}")

    def umat(self):
        """The isochoric FElupe material (imports FElupe)."""
        import felupe as fem

        if self.model == "neo_hookean":
            return fem.NeoHooke(mu=self.constants[0])
        if self.model == "yeoh":
            c10, c20, c30 = self.constants
            return fem.Hyperelastic(fem.yeoh, C10=c10, C20=c20, C30=c30)
        mu, alpha = self.constants
        return fem.Hyperelastic(fem.ogden, mu=[mu], alpha=[alpha])


def preset(model: str, grade_key: str, shear_modulus_mpa: float | None = None) -> Hyperelastic:
    """The ``model`` preset of silicone ``grade_key``, scaled so its initial shear modulus is
    ``shear_modulus_mpa`` (MPa; default the preset's own: neo-Hookean μ from the 100 % modulus, Yeoh 2·C10,
    Ogden μ). A grade without a sourced Yeoh/Ogden fit falls back to its neo-Hookean μ (Yeoh C20 = C30 = 0,
    Ogden α = 2 are neo-Hookean) and the note says so. Raises ValueError for an unknown model or grade."""
    if model not in MODELS:
        raise ValueError(f"{model!r} invalid, must be one of {', '.join(MODELS)}")
    g = grade_record(grade_key)
    mu_nh = g.neo_hookean_mu_mpa
    if model == "neo_hookean":
        constants, g0, note = (mu_nh,), mu_nh, f"neo-Hookean, mu from the 100 % modulus ({g.source})"
    elif model == "yeoh" and g.yeoh_c_mpa is not None:
        constants, g0, note = g.yeoh_c_mpa, 2 * g.yeoh_c_mpa[0], f"Yeoh: {g.hyperelastic_source}"
    elif model == "ogden" and g.ogden_mu_alpha is not None:
        constants, g0, note = g.ogden_mu_alpha, g.ogden_mu_alpha[0], f"one-term Ogden: {g.hyperelastic_source}"
    else:
        constants = (mu_nh / 2, 0.0, 0.0) if model == "yeoh" else (mu_nh, 2.0)
        g0, note = mu_nh, f"{g.label} has no sourced {model} fit: neo-Hookean-equivalent {model} constants"
    if shear_modulus_mpa is None:
        return Hyperelastic(model, tuple(constants), g0, note)
    s = shear_modulus_mpa / g0
    scaled = (constants[0] * s, constants[1]) if model == "ogden" else tuple(c * s for c in constants)
    return Hyperelastic(model, scaled, shear_modulus_mpa, f"{note}; scaled to G = {shear_modulus_mpa:g} MPa")
