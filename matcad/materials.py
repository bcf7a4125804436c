"""Cast silicones matcad knows: one sourced record per grade, used by the wall model, the cap mechanics and the
casting guide. Values are the manufacturers' technical data sheets unless a line says otherwise; see
``docs/materials.md`` for the sources and the derivations. The neck plate's acrylic modulus
(:data:`ACRYLIC_MODULUS_MPA`) is here too.

Units: density kg/m³, moduli MPa, times minutes or hours as named, temperatures °C.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SiliconeGrade:
    """One cast silicone.

    ``shear_modulus_mpa`` is the static (quasi-static test-rate) small-strain shear modulus range the band
    carries; ``modulus_100_mpa`` the data sheet's nominal stress at 100 % elongation (uniaxial), from which
    ``neo_hookean_mu_mpa`` = σ₁₀₀ / (λ − λ⁻²) at λ = 2 is derived. ``yeoh_c_mpa`` (C10, C20, C30) and
    ``ogden_mu_alpha`` (μ in MPa, α; one term, W = 2μ/α² (λ₁^α + λ₂^α + λ₃^α − 3)) are the large-strain presets
    of the cap mechanics, ``None`` when no sourced fit exists (the mechanics then says it falls back to
    neo-Hookean); ``hyperelastic_source`` says where they come from.
    """

    key: str
    label: str
    density_kg_m3: float
    shear_modulus_mpa: tuple[float, float]
    modulus_100_mpa: float | None
    shore: str
    mix_ratio: str
    pot_life_min: float
    cure_h_room: float
    viscosity_cps: float
    tensile_mpa: float
    elongation_pct: float
    source: str
    yeoh_c_mpa: tuple[float, float, float] | None = None
    ogden_mu_alpha: tuple[float, float] | None = None
    hyperelastic_source: str = ""
    loss_factor: tuple[float, float] = (0.1, 0.2)
    """Shear loss factor η = G''/G' at 1-10 kHz (the wall model's G* = G(1 + iη))."""
    khz_modulus_factor: tuple[float, float] = (1.0, 1.6)
    """Storage modulus at 1-10 kHz over the static ``shear_modulus_mpa`` (elastomers stiffen with rate)."""
    dynamic_source: str = ""

    @property
    def neo_hookean_mu_mpa(self) -> float:
        """Initial shear modulus of the neo-Hookean model through the 100 % modulus (λ = 2), MPa."""
        if self.modulus_100_mpa is None:
            return (self.shear_modulus_mpa[0] * self.shear_modulus_mpa[1]) ** 0.5
        return self.modulus_100_mpa / (2.0 - 2.0 ** -2)


PSI_MPA = 0.006894757

GRADES: dict[str, SiliconeGrade] = {g.key: g for g in (
    SiliconeGrade(
        key="dragon_skin_30", label="Smooth-On Dragon Skin 30", density_kg_m3=1080.0,
        shear_modulus_mpa=(0.2, 0.6), modulus_100_mpa=86 * PSI_MPA, shore="30A", mix_ratio="1A:1B by weight",
        pot_life_min=45.0, cure_h_room=16.0, viscosity_cps=20000.0, tensile_mpa=500 * PSI_MPA,
        elongation_pct=364.0,
        source="Smooth-On Dragon Skin Series technical bulletin (specific gravity 1.08, 100 % modulus 86 psi)",
        yeoh_c_mpa=(0.1536, 0.0016, 0.0), ogden_mu_alpha=(0.3098, 2.072),
        hyperelastic_source="Yeoh C10 = 0.1536, C20 = 0.0016 MPa: a published uniaxial fit for Dragon Skin 30 "
                            "(quoted in the project's physics notes, original not re-checked); Ogden: "
                            "least-squares fit of one term to that Yeoh curve in uniaxial stress, "
                            "stretch 0.6-2.0 (docs/materials.md)",
        loss_factor=(0.1, 0.2), khz_modulus_factor=(1.0, 1.6),
        dynamic_source="no kHz data sheet value exists; eta 0.1-0.2 and a modulus rise with frequency are the "
                       "range reported for platinum-cure silicone rubbers of this hardness (matcad's physics "
                       "notes); the 1.0-1.6 factor is matcad's stated assumption, to be replaced by a DMA "
                       "measurement"),
    SiliconeGrade(
        key="ecoflex_00_30", label="Smooth-On Ecoflex 00-30", density_kg_m3=1070.0,
        shear_modulus_mpa=(0.02, 0.06), modulus_100_mpa=10 * PSI_MPA, shore="00-30",
        mix_ratio="1A:1B by weight", pot_life_min=45.0, cure_h_room=4.0, viscosity_cps=3000.0,
        tensile_mpa=200 * PSI_MPA, elongation_pct=900.0,
        source="Smooth-On Ecoflex Series technical bulletin (specific gravity 1.07, 100 % modulus 10 psi)",
        loss_factor=(0.1, 0.3), khz_modulus_factor=(1.0, 2.0),
        dynamic_source="no kHz data sheet value; a very soft, lightly crosslinked grade: matcad assumes a wider "
                       "loss (0.1-0.3) and rate-stiffening (1.0-2.0) range than Dragon Skin 30"),
    SiliconeGrade(
        key="sylgard_184", label="Dow Sylgard 184 (10:1)", density_kg_m3=1030.0,
        shear_modulus_mpa=(0.44, 1.0), modulus_100_mpa=None, shore="43A", mix_ratio="10:1 base:curing agent by weight",
        pot_life_min=90.0, cure_h_room=48.0, viscosity_cps=3500.0, tensile_mpa=6.7, elongation_pct=140.0,
        source="Dow Sylgard 184 technical data sheet; E = 1.32-2.97 MPa by cure temperature, Johnston et al., "
               "J. Micromech. Microeng. 24 (2014) 035017, G = E/3",
        loss_factor=(0.05, 0.15), khz_modulus_factor=(1.0, 1.5),
        dynamic_source="no kHz data sheet value; an unfilled, well crosslinked PDMS: matcad assumes lower loss "
                       "(0.05-0.15) and 1.0-1.5 rate-stiffening"),
)}
DEFAULT_GRADE = "dragon_skin_30"


def grade(key: str) -> SiliconeGrade:
    """The silicone registered under ``key``. Raises ValueError listing the known grades."""
    try:
        return GRADES[key]
    except KeyError:
        raise ValueError(f"{key!r} invalid, must be one of {', '.join(GRADES)}") from None


ACRYLIC_MODULUS_MPA = 3300.0
"""Young's modulus of cast acrylic (PMMA) sheet, the neck plate's: 3300 MPa, Röhm PLEXIGLAS GS product information
(tensile modulus, ISO 527-2/1B/1, 23 °C). Extruded sheet is within ~5 % of it."""
