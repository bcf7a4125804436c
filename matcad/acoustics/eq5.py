"""Paper Eq. 5: a taxel's pitch under a normal load, its inverse, its uncertainty, and its fit to measured pairs.
Forces N, frequencies Hz, volumes mm³, temperatures °C.

    f(F) = sqrt(K / V_eff(F)),   V_eff(F) = V0 − a·F² − b·F,   K = c²A/(4π² l)      (paper Eqs. 2–5)

Linear in disguise: K/f² = V0 − bF − aF², so the inverse is a quadratic root and the fit is least squares.
:class:`Eq5` is the one type for it everywhere: the paper's published constants, a spec's [calibration], a fit to
measured pairs (with the covariance of (V0, b, a), the residual and between-cycle scatter that sensing turns into
force intervals), and the fit of the cap mechanics' predicted curve.

The paper's constants (V0 = 32.21 mm³, a = −0.0086, b = 0.4626) reproduce its measured band only with A = d²/4 (π
dropped); with the physical A = πd²/4 they give ~7.1 kHz. Each Eq5 therefore carries its area convention, and the
paper's is :data:`MAT_PAPER_2024` with ``area_convention = "d2/4"``, never mixed silently with physical volumes. Its
constants are not tied to a neck: :meth:`Eq5.bound` gives K from a geometry and air (c, d, l).

Outside the fitted law's meaning — past the V_eff minimum at F = −b/(2a) (a < 0), or V_eff ≤ 0 — the frequency is
NaN and :meth:`Eq5.invalid_reason` says why; never an extrapolated number.

Fitting it to (F, f) pairs is :mod:`matcad.acoustics.eq5fit`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from matcad.acoustics.models import MM_PER_M

AREA_CONVENTIONS = ("pi_d2/4", "d2/4")
RANGE_TOLERANCE = 0.02
"""Forces within 2 % of the calibrated span beyond its ends still count as inside it."""
KELVIN = 273.15
TEMPERATURE_RANGE_C = (-60.0, 100.0)
"""Air temperatures a recording may be corrected for (°C)."""


def t_quantile(p: float, dof: int) -> float:
    """Student's t quantile."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, p))


def convention_area_mm2(neck_diameter_mm, area_convention):
    """Neck area under a calibration's convention: πd²/4 ('pi_d2/4') or d²/4 ('d2/4') (mm²)."""
    scale = {"pi_d2/4": np.pi / 4.0, "d2/4": 0.25}[area_convention]
    return scale * np.square(neck_diameter_mm)


def frequency_constant_mm3_hz2(speed_of_sound_m_s, neck_diameter_mm, neck_length_mm, area_convention="pi_d2/4"):
    """K = c²A/(4π² l) in mm³·Hz², so that f² = K / V_eff (c m/s, d and l mm)."""
    c = np.asarray(speed_of_sound_m_s, dtype=float) * MM_PER_M
    return c * c * convention_area_mm2(neck_diameter_mm, area_convention) / (4 * np.pi**2 * neck_length_mm)


@dataclass(frozen=True)
class Eq5:
    """Paper Eq. 5 constants and what is known of their uncertainty.

    ``v0_mm3`` (mm³), ``a`` (mm³/N²), ``b`` (mm³/N); ``k_mm3_hz2`` the K they go with (None: constants not yet
    tied to a neck, see :meth:`bound`); the area convention they were fit with and a name. From a fit: the
    covariance of (V0, b, a) (9 numbers row by row), the residual scatter in K/f² (mm³) and its degrees of freedom,
    the force range measured (N), the between-cycle (hysteresis) scatter in K/f² (mm³) and the air temperature
    (°C) during calibration."""

    v0_mm3: float
    a: float
    b: float
    k_mm3_hz2: float | None = None
    area_convention: str = "pi_d2/4"
    name: str = "spec"
    covariance: tuple[float, ...] | None = None
    residual_std_mm3: float | None = None
    dof: int | None = None
    force_range_n: tuple[float, float] | None = None
    cycle_std_mm3: float = 0.0
    temperature_c: float | None = None

    def __post_init__(self):
        if self.area_convention not in AREA_CONVENTIONS:
            raise ValueError(f"area_convention {self.area_convention!r} invalid, must be one of "
                             f"{AREA_CONVENTIONS}")

    # --- the law --------------------------------------------------------------------------------------------------
    def bound(self, speed_of_sound_m_s: float, neck_diameter_mm: float, neck_length_mm: float) -> Eq5:
        """These constants with K from the air and neck (m/s, mm) under their area convention; unchanged when they
        carry their own K (a fit's)."""
        if self.k_mm3_hz2 is not None:
            return self
        k = frequency_constant_mm3_hz2(speed_of_sound_m_s, neck_diameter_mm, neck_length_mm, self.area_convention)
        return dataclasses.replace(self, k_mm3_hz2=float(k))

    def _k(self) -> float:
        if self.k_mm3_hz2 is None:
            raise ValueError(f"Eq. 5 constants {self.name!r} are not tied to a neck yet (no K): bind them first")
        return self.k_mm3_hz2

    @property
    def turn_force_n(self) -> float:
        """Force where V_eff stops falling, −b/(2a) (N); +inf when a ≥ 0 (no minimum ahead)."""
        return -self.b / (2.0 * self.a) if self.a < 0 else np.inf

    def volume_mm3(self, force_n):
        """V_eff = V0 − aF² − bF (mm³), paper Eqs. 3–4."""
        f = np.asarray(force_n, dtype=float)
        with np.errstate(invalid="ignore", over="ignore"):
            return self.v0_mm3 - self.a * f * f - self.b * f

    def invalid_reason(self, force_n) -> str:
        """Why Eq. 5 has no meaning at this force (N), or '' when it does."""
        f_min = self.turn_force_n
        if not np.isfinite(force_n):
            return "force is not finite"
        if force_n > f_min:
            return (f"F = {force_n:g} N is past the V_eff minimum at {f_min:.3g} N, where the fitted model "
                    "turns back (frequency would fall with force)")
        if self.volume_mm3(force_n) <= 0:
            return f"V_eff = {float(self.volume_mm3(force_n)):.4g} mm^3 <= 0 at F = {force_n:g} N"
        return ""

    def frequency_hz(self, force_n):
        """f(F) (Hz), NaN where :meth:`invalid_reason` is not empty. Vectorised over ``force_n`` (N)."""
        f = np.asarray(force_n, dtype=float)
        v = self.volume_mm3(f)
        ok = np.isfinite(f) & (f <= self.turn_force_n) & (v > 0)
        return np.where(ok, np.sqrt(self._k() / np.where(ok, v, 1.0)), np.nan)

    def force_n(self, frequency_hz):
        """The force F (N) at which the taxel sings at ``frequency_hz`` (Hz): the inverse of Eq. 5. Vectorised.

        Solves aF² + bF + C = 0 with C = K/f² − V0 on the branch below the V_eff minimum. For b > 0 it uses the
        cancellation-free form F = −2C / (b + sqrt(b² − 4aC)), which tends to the linear root −C/b as a → 0.
        NaN where no valid force gives that frequency.
        """
        f = np.asarray(frequency_hz, dtype=float)
        a, b = self.a, self.b
        with np.errstate(divide="ignore", invalid="ignore"):
            c = self._k() / (f * f) - self.v0_mm3
            disc = b * b - 4.0 * a * c
            s = np.sqrt(disc)
            if b > 0:
                force = -2.0 * c / (b + s)
            elif a != 0:
                force = (-b + s) / (2.0 * a)
            elif b != 0:
                force = -c / b
            else:
                force = np.full_like(c, np.nan)
        ok = (f > 0) & np.isfinite(force) & (disc >= 0) & (force <= self.turn_force_n)
        return np.where(ok, force, np.nan)

    def slope_hz_per_n(self, force_n):
        """df/dF (Hz/N) at ``force_n`` (N): f·(b + 2aF)/(2 V_eff), from f² V_eff = K."""
        f = np.asarray(force_n, dtype=float)
        return self.frequency_hz(f) * (self.b + 2 * self.a * f) / (2.0 * self.volume_mm3(f))

    def rise(self, max_force_n: float, points: int = 65) -> tuple[float, float]:
        """(min, max) of f(F)/f(0) over 0 <= F <= ``max_force_n`` (N), sampled at ``points`` forces (f may turn
        back inside the range); independent of K and of the area convention. ValueError past where it holds."""
        why = self.invalid_reason(max_force_n)
        if why:
            raise ValueError(why)
        v = self.volume_mm3(np.linspace(0.0, max_force_n, points))
        ratio = np.sqrt(v[0] / v)
        return float(ratio.min()), float(ratio.max())

    # --- sensing: force and its interval --------------------------------------------------------------------------
    def temperature_factor(self, temperature_c: float | None) -> float:
        """sqrt(T_cal/T) that maps a frequency heard at ``temperature_c`` (°C) to calibration conditions (1 when
        either temperature is unknown): f follows the speed of sound, c ∝ sqrt(T) (ideal gas). Raises ValueError
        when only the recording's is known."""
        if temperature_c is None:
            return 1.0
        lo, hi = TEMPERATURE_RANGE_C
        if not lo <= temperature_c <= hi:
            raise ValueError(f"--temperature-c {temperature_c:g} invalid, must be {lo:g} to {hi:g} degC")
        if self.temperature_c is None:
            raise ValueError("--temperature-c needs a calibration that records its temperature_c (calibrate with "
                             "--temperature-c)")
        return float(np.sqrt((self.temperature_c + KELVIN) / (temperature_c + KELVIN)))

    def frequency_range_hz(self) -> tuple[float, float]:
        """The frequencies (Hz) at the ends of the calibrated force range, low first."""
        ends = [float(np.sqrt(self._k() / self.volume_mm3(f))) for f in self.force_range_n]
        return min(ends), max(ends)

    @property
    def cov(self) -> np.ndarray:
        """The covariance of (V0, b, a) as a 3 × 3 array."""
        return np.array(self.covariance, dtype=float).reshape(3, 3)

    def force_with_interval(self, frequency_hz, level: float = 0.95, temperature_c=None,
                            temperature_sd_c: float = 0.0):
        """(force, half-width of its ``level`` interval) (N) at each frequency (Hz) heard at ``temperature_c``
        (°C); NaN outside the calibrated force range (within :data:`RANGE_TOLERANCE` of its span). The interval
        combines, by the delta method, the parameter covariance Σ, the residual scatter σ², the between-cycle
        variance τ² and, when the air's temperature now is not known exactly, its standard deviation
        ``temperature_sd_c`` (°C) against the calibration's (y = K/f² ∝ 1/T, so σ_y = y·σ_T/T):
        Var F = gᵀ Σ g + (σ² + τ² + σ_y²)/(b + 2aF)², g = ∂F/∂(V0, b, a) = (1, −F, −F²) / (b + 2aF)."""
        f = np.asarray(frequency_hz, dtype=float) * self.temperature_factor(temperature_c)
        force = self.force_n(f)
        lo, hi = self.force_range_n
        slack = RANGE_TOLERANCE * (hi - lo)
        force = np.where((force >= lo - slack) & (force <= hi + slack), force, np.nan)
        slope = self.b + 2 * self.a * force  # −∂y/∂F
        grad = np.stack([np.ones_like(force), -force, -force * force]) / slope
        kelvin = (20.0 if self.temperature_c is None else self.temperature_c) + KELVIN
        with np.errstate(divide="ignore", invalid="ignore"):
            air = self._k() / (f * f) * temperature_sd_c / kelvin
        scatter = self.residual_std_mm3 ** 2 + self.cycle_std_mm3 ** 2 + air ** 2
        var = np.einsum("i...,ij,j...->...", grad, self.cov, grad) + scatter / slope ** 2
        return force, t_quantile(0.5 + level / 2, self.dof) * np.sqrt(var)

    def frequency_bands_hz(self, forces_n, level: float = 0.95):
        """(confidence low, high, prediction low, high) of f at ``forces_n`` (N) (Hz); the prediction band holds a
        new cycle's point (residual and between-cycle scatter)."""
        f = np.asarray(forces_n, dtype=float)
        x = np.column_stack([np.ones_like(f), -f, -f * f])
        y = x @ np.array([self.v0_mm3, self.b, self.a])
        var_mean = np.einsum("ij,jk,ik->i", x, self.cov, x)
        t = t_quantile(0.5 + level / 2, self.dof)
        half_c = t * np.sqrt(var_mean)
        half_p = t * np.sqrt(var_mean + self.residual_std_mm3 ** 2 + self.cycle_std_mm3 ** 2)
        k = self._k()
        to_f = lambda v: np.sqrt(k / np.maximum(v, 1e-300))  # noqa: E731  (f falls as y grows)
        return to_f(y + half_c), to_f(y - half_c), to_f(y + half_p), to_f(y - half_p)

    def to_toml(self, table: str = "calibration") -> str:
        """A [calibration] table that a spec accepts as it is (``table`` "taxel.calibration": the same fields as
        one [[taxel]] entry's sub-table)."""
        import tomli_w  # the TOML writer the project depends on: quoting, floats and nesting done right

        given = {"v0_mm3": self.v0_mm3, "a": self.a, "b": self.b, "area_convention": "pi_d2/4",
                 "k_mm3_hz2": self.k_mm3_hz2, "force_range_n": self.force_range_n, "covariance": self.covariance,
                 "residual_std_mm3": self.residual_std_mm3, "dof": self.dof, "cycle_std_mm3": self.cycle_std_mm3,
                 "temperature_c": self.temperature_c}
        fields = {k: (v if isinstance(v, str) else int(v) if k == "dof" else
                      [float(x) for x in v] if isinstance(v, (tuple, list)) or hasattr(v, "__len__") else float(v))
                  for k, v in given.items() if v is not None}
        nested: dict = fields
        for key in reversed(table.split(".")):
            nested = {key: nested}
        return "# written by `matcad calibrate`: paper Eq. 5, V_eff = v0 - a F^2 - b F\n" + tomli_w.dumps(nested)


MAT_PAPER_2024 = Eq5(v0_mm3=32.21, a=-0.0086, b=0.4626, area_convention="d2/4", name="mat-paper-2024")
"""The paper's fit (Fig. 9 and §VI), valid below ~26.9 N, with the paper's own A = d²/4 convention."""
