"""The prediction ladder, cheapest first. Pure, vectorised functions (numpy arrays in, arrays out).

Units: lengths mm, areas mm², volumes mm³, speed of sound m/s, shear modulus Pa, frequencies Hz.

Rungs:
1. :func:`lumped_hz` — paper Eq. 1 (Helmholtz/Rayleigh), optional c_f·ξ correction.
2. :func:`end_corrected_hz` — Eq. 1 with the neck lengthened by its two end corrections.
3. :func:`transmission_line_hz` — plane waves in neck and cavity (Selamet et al., JASA 101(1), 1997); the
   default for rigid walls; valid from A ≪ S up to A = S.
4. :func:`soft_wall_length_scale` feeds rung 3 with a quasi-static (massless) compliant wall; valid only when
   the cap's wall modes lie ≥ 3× f. The silicone default is :mod:`matcad.acoustics.wall` (wall modes with mass
   and loss), which moves f up when those modes lie below f, as they do for the paper's Dragon Skin cap.
"""

import functools

import numpy as np

from matcad.acoustics.air import BULK_MODULUS_PA

MM_PER_M = 1e3
INGARD_XI_LIMIT = 0.4
"""Ingard (1953) states his orifice correction for ξ = d/D < 0.4 only."""
HALF_SPACE_MEAN_DISPLACEMENT = 16.0 * 0.75 / (3.0 * np.pi * 3.0)
"""Mean normal displacement of an incompressible half-space under uniform pressure p on a disc of radius a,
w̄ = 16(1-ν²) p a / (3π E) with ν = 1/2, E = 3G, i.e. 0.4244 p a / G (Johnson, Contact Mechanics, §3.4)."""


def _c_mm_s(speed_of_sound_m_s):
    return np.asarray(speed_of_sound_m_s, dtype=float) * MM_PER_M


def baffled_end_correction_mm(neck_radius_mm):
    """Outer end correction of a neck opening into an infinite flat baffle: 8a/(3π) ≈ 0.849a (mm), Rayleigh."""
    return 8.0 * np.asarray(neck_radius_mm, dtype=float) / (3.0 * np.pi)


def unflanged_end_correction_mm(neck_radius_mm):
    """Outer end correction of a thin unflanged tube end: 0.6133a (mm), Levine & Schwinger 1948."""
    return 0.6133 * np.asarray(neck_radius_mm, dtype=float)


def mount_end_correction_mm(neck_radius_mm, gap_mm, gap_radius_mm):
    """Outer end correction of a flanged mouth with a parallel surface (the air-supply mount) ``gap_mm`` below.

    Baffled correction plus the inertance of radial flow in the gap from r = a + h out to the gap's vent
    radius R_g, expressed as neck length: a²/(2h)·ln(R_g/(a+h)) (docs/physics.md; radial-flow inertance
    ρ ln(R2/R1)/(2πh)). Clipped at zero when a + h ≥ R_g. Tends to the baffled value as h grows (mm).
    """
    a = np.asarray(neck_radius_mm, dtype=float)
    h = np.asarray(gap_mm, dtype=float)
    radial = a * a / (2.0 * h) * np.log(np.maximum(gap_radius_mm / (a + h), 1.0))
    return baffled_end_correction_mm(a) + radial


def _simpson(f, step):
    """Simpson's rule along the last axis of an odd number of samples ``f`` spaced ``step`` apart."""
    return step / 3.0 * (f[..., 0] + f[..., -1] + 4.0 * f[..., 1:-1:2].sum(axis=-1) + 2.0 * f[..., 2:-1:2].sum(axis=-1))


HANKEL_BLOCK = 1024
"""Arguments per pass of :func:`hankel2_ratio` (its quadrature holds ~130 samples of each: memory stays small)."""


def hankel2_ratio(x):
    """H₀⁽²⁾(x)/H₁⁽²⁾(x) for x > 0 (floats or arrays), Hₙ⁽²⁾ = Jₙ − i Yₙ from the Bessel functions' integral
    representations (DLMF 10.9.1 and 10.9.6: Jₙ = (1/π)∫₀^π cos(nτ − x sin τ) dτ, Yₙ = (1/π)∫₀^π sin(x sin τ − nτ) dτ
    − (1/π)∫₀^∞ (e^{nt} + (−1)ⁿ e^{−nt}) e^{−x sinh t} dt) by Simpson's rule: within 1e-4 of scipy's over
    0.02 ≤ x ≤ 5 (tested; a neck's x = k(a + h) stays below 2), without loading scipy.special on `predict`'s path."""
    x = np.asarray(x, dtype=float)
    flat = x.reshape(-1)
    out = np.empty(flat.shape, dtype=complex)
    tau = np.linspace(0.0, np.pi, 65)
    for start in range(0, len(flat), HANKEL_BLOCK):
        xs = flat[start:start + HANKEL_BLOCK, None]
        end = np.arcsinh(50.0 / xs)  # e^{−x sinh t} < e^{−50} beyond
        t = np.linspace(0.0, 1.0, 129) * end
        h = []
        for n in (0, 1):
            j = _simpson(np.cos(n * tau - xs * np.sin(tau)), tau[1]) / np.pi
            tail = _simpson((np.exp(n * t) + (-1) ** n * np.exp(-n * t)) * np.exp(-xs * np.sinh(t)), end[:, 0] / 128)
            h.append(j - 1j * (_simpson(np.sin(xs * np.sin(tau) - n * tau), tau[1]) - tail) / np.pi)
        out[start:start + HANKEL_BLOCK] = h[0] / h[1]
    return out.reshape(x.shape) if x.ndim else complex(out[0])


def radiating_gap_end_correction_mm(neck_radius_mm, gap_mm, wavenumber_per_mm):
    """Outer end correction of the mount's mouth (mm) when the gap radiates outward at its far edge, where
    :func:`mount_end_correction_mm` releases the pressure: the baffled correction plus the mass reactance of an
    outgoing cylindrical wave p ∝ H₀⁽²⁾(kr) in the gap from r = a + h (time e^{iωt}; Morse & Ingard 1968,
    Theoretical Acoustics §7.1), a²/(2h)·Re[H₀⁽²⁾(x)/H₁⁽²⁾(x)]/x at x = k(a + h). For x → 0 it is the radial
    inertance out to R = 2/(k e^γ) ≈ 1.123/k, whatever the gap's extent (docs/physics.md)."""
    a = np.asarray(neck_radius_mm, dtype=float)
    h = np.asarray(gap_mm, dtype=float)
    x = np.asarray(wavenumber_per_mm, dtype=float) * (a + h)
    log_x, values = _gap_reactance_table()
    small = np.log(2.0 / (x * np.exp(np.euler_gamma)))  # below the table: the x → 0 limit
    per_x = np.where(x < np.exp(log_x[0]), small, np.interp(np.log(x), log_x, values))
    return baffled_end_correction_mm(a) + a * a / (2.0 * h) * per_x


@functools.lru_cache(maxsize=1)
def _gap_reactance_table():
    """Re[H₀⁽²⁾(x)/H₁⁽²⁾(x)]/x at 257 log-spaced x over 1e-3 … 50 (ln x, values; ~3 ms once): interpolated linearly
    in ln x it is within 1e-3 of scipy's (tested), so a sweep's arrays pay a lookup."""
    x = np.geomspace(1e-3, 50.0, 257)
    return np.log(x), hankel2_ratio(x).real / x


def mouth_end_correction_mm(mouth, neck_radius_mm, gap_mm, gap_radius_mm):
    """Outer end correction for the spec's ``neck.mouth`` choice (mm)."""
    if mouth == "baffled":
        return baffled_end_correction_mm(neck_radius_mm)
    if mouth == "unflanged":
        return unflanged_end_correction_mm(neck_radius_mm)
    if mouth == "mount":
        return mount_end_correction_mm(neck_radius_mm, gap_mm, gap_radius_mm)
    raise ValueError(f"mouth {mouth!r} invalid, must be one of 'baffled', 'unflanged', 'mount'")


def ingard_end_correction_mm(neck_diameter_mm, cavity_diameter_mm):
    """Inner (orifice-into-cavity) correction 0.48·sqrt(A)·(1 − 1.25ξ) (mm), Ingard, JASA 25, 1953.

    Stated valid for ξ = d/D < 0.4 only; clipped at zero where the formula turns negative (ξ > 0.8).
    """
    d = np.asarray(neck_diameter_mm, dtype=float)
    xi = d / cavity_diameter_mm
    return np.maximum(0.48 * np.sqrt(np.pi) * d / 2.0 * (1.0 - 1.25 * xi), 0.0)


def step_end_correction_mm(neck_diameter_mm, cavity_diameter_mm):
    """Inner correction of an axisymmetric step d → D for the whole range 0 < ξ ≤ 1 (mm).

    0.82a(1 − 1.35ξ + 0.31ξ³), Kergomard & Garcia, J. Sound Vib. 114(3), 1987: tends to the flanged value
    0.82a as ξ → 0; clipped at zero near ξ = 1 where there is no step (the fit gives −0.033a there).
    """
    a = np.asarray(neck_diameter_mm, dtype=float) / 2.0
    xi = 2.0 * a / cavity_diameter_mm
    return np.maximum(0.82 * a * (1.0 - 1.35 * xi + 0.31 * xi**3), 0.0)


def lumped_hz(speed_of_sound_m_s, neck_area_mm2, cavity_volume_mm3, neck_length_mm, c_f=0.0, xi=0.0):
    """Helmholtz resonance, paper Eq. 1: f = c/(2π)·sqrt(A / (V_c·l·(1 + c_f·ξ))) (Hz).

    With c_f = 0 (the default) this is the uncorrected lumped model; it assumes kl, kL ≪ 1 and
    A·l ≪ V_c, and overestimates the paper's taxel by ~23 %.
    """
    return (_c_mm_s(speed_of_sound_m_s) / (2.0 * np.pi)
            * np.sqrt(neck_area_mm2 / (cavity_volume_mm3 * neck_length_mm * (1.0 + c_f * xi))))


def end_corrected_hz(speed_of_sound_m_s, neck_area_mm2, cavity_volume_mm3, effective_neck_length_mm):
    """Eq. 1 (c_f = 0) with the neck's effective length l + δ_outer + δ_inner (Hz), Rayleigh/Ingard."""
    return lumped_hz(speed_of_sound_m_s, neck_area_mm2, cavity_volume_mm3, effective_neck_length_mm)


def transmission_line_wavenumber(area_ratio, neck_length_mm, cavity_length_mm, side_length_mm=0.0,
                                 cone_per_mm=0.0, rtol=1e-13, max_iter=100):
    """Fundamental root k (1/mm) of tan(k·l)·(tan(k·L) + k·s) = r·(1 − q·tan(k·l)/k), with r = A/S (Selamet et
    al. 1997), s = V_side/S the length of cavity that a volume V_side of air joined to the cavity at the neck would
    add (a lumped compliance at the neck-cavity junction) and q = σ/R the cone of a tapered neck (σ = dR/dx, its
    radius growing towards the cavity, R its radius there, A = πR²). s = q = 0: tan(k·l)·tan(k·L) = r.

    The fundamental is the only root with both tangents on their first branch, k in (0, π/(2M)), M = max(l, L).
    In u = ln k, Φ(u) = ln tan(kl) + ln(tan(kL) + ks) − ln r − ln(1 − q·tan(kl)/k) increases (each factor does for
    q ≥ 0; a cone narrowing to the cavity, q < 0, is checked against the bracket); for s = q = 0 it is also convex
    (d ln tan x / d ln x = 2x/sin 2x grows with x). The start is right of the root and left of the pole: the
    smaller of the lumped guess sqrt(r(1 − ql)/(l(L + s))) (tan x ≥ x) and, for s = q = 0,
    π·sqrt(r/(8mM + 4rM²)), m = min(l, L) (tan x ≥ 8x/(π² − 4x²) on the longer segment), else 0.99 of the pole.
    Newton in u then descends onto the fundamental in ~5 steps and never jumps to an overtone; a bisection
    safeguard inside the bracket (Φ = +∞ where 1 − q·tan(kl)/k ≤ 0) guards against rounding. Broadcasts over
    array inputs; an entry stops iterating once it has converged, so its root is the same whether it is solved
    alone or among a sweep's variants (of the same kind: plain, or with joined air or a cone).
    """
    r, ln, lc, side, q = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (
        area_ratio, neck_length_mm, cavity_length_mm, side_length_mm, cone_per_mm)))
    long, short = np.maximum(ln, lc), np.minimum(ln, lc)
    lo = np.zeros_like(r)
    hi = np.pi / (2.0 * long)
    plain = not (np.any(side) or np.any(q))
    if plain:
        k = np.minimum(np.sqrt(r / (ln * lc)), np.pi * np.sqrt(r / (8.0 * short * long + 4.0 * r * long * long)))
    else:
        k = np.minimum(np.sqrt(r * (1.0 - q * ln) / (ln * (lc + side))), 0.99 * hi)
    active = np.ones(k.shape, dtype=bool)  # a converged root stays as it is: each entry's iterates are its own
    for _ in range(max_iter):
        t1, t2 = np.tan(k * ln), np.tan(k * lc)
        if plain:
            phi = np.log(t1 * t2 / r)
            dphi_du = k * (ln * (t1 + 1.0 / t1) + lc * (t2 + 1.0 / t2))
        else:
            t2s = t2 + k * side
            cone = 1.0 - q * t1 / k
            with np.errstate(divide="ignore", invalid="ignore"):
                phi = np.where(cone > 0.0, np.log(t1 * t2s / (r * cone)), np.inf)
                dphi_du = (k * (ln * (t1 + 1.0 / t1) + (lc * (1.0 + t2 * t2) + side) / t2s)
                           + q * (ln * (1.0 + t1 * t1) - t1 / k) / cone)
        lo = np.where(phi < 0.0, k, lo)
        hi = np.where(phi > 0.0, k, hi)
        with np.errstate(over="ignore", invalid="ignore"):
            newton = k * np.exp(-phi / dphi_du)
        k_new = np.where((newton >= lo) & (newton <= hi), newton, 0.5 * (lo + hi))
        converged = np.abs(k_new - k) <= rtol * k_new
        k = np.where(active, k_new, k)
        active &= ~converged
        if not active.any():
            break
    return k


def transmission_line_hz(speed_of_sound_m_s, neck_area_mm2, cavity_area_mm2, effective_neck_length_mm,
                         cavity_length_mm, wall_length_factor=1.0, wall_extra_length_mm=0.0, side_volume_mm3=0.0,
                         neck_cone_mm=None):
    """Fundamental of the neck + closed-cavity transmission line (Hz), Selamet et al., JASA 101(1), 1997.

    Plane waves in a neck (area A, effective length l + end corrections, open end) and a cavity (area S,
    length L, closed end); resonance where tan(k·l_eff)·tan(k·L) = A/S. Limits: the lumped Eq. 1 as
    kl, kL → 0; a quarter-wave tube of length l_eff + L when A = S.

    A compliant cavity wall (see :func:`soft_wall_length_scale`) slows waves in the cavity by
    n = ``wall_length_factor`` and adds ``wall_extra_length_mm`` of closed-end compliance; the equation
    becomes tan(k·l_eff)·tan(k·n·L') = A/(n·S) with L' = L + extra, the same form, solved the same way.
    ``side_volume_mm3`` of air joined to the cavity at the neck (gaps in the stack) is a compliance V/(ρc²) in
    parallel with the cavity at the junction: tan(k·l_eff)·(tan(k·n·L') + k·V/(n·S)) = A/(n·S); in the lumped
    limit it adds V to the cavity volume.
    ``neck_cone_mm`` = (R_m, R_c), the radii at the mouth and cavity ends of a tapered neck of length l_eff (a
    cone, its end corrections included): spherical waves p = sin(k·x)/(x − x_apex) in the neck, whose admittance
    at the cavity is (A_c/ρc)·(cot(k·l_eff) − σ/(k·R_c)), σ = (R_c − R_m)/l_eff, A_c = πR_c²; the right side
    becomes A_c/(n·S)·(1 − σ·tan(k·l_eff)/(k·R_c)). Its lumped limit is the cone's inertance ρ·l_eff/(πR_m·R_c),
    and ``neck_area_mm2`` is then unused.
    """
    n = np.asarray(wall_length_factor, dtype=float)
    cavity_area = np.asarray(cavity_area_mm2, dtype=float)
    neck_area, cone = np.asarray(neck_area_mm2, dtype=float), 0.0
    if neck_cone_mm is not None:
        r_mouth, r_cavity = (np.asarray(x, dtype=float) for x in neck_cone_mm)
        neck_area = np.pi * r_cavity**2
        cone = (r_cavity - r_mouth) / np.asarray(effective_neck_length_mm, dtype=float) / r_cavity
    k = transmission_line_wavenumber(neck_area / (cavity_area * n), effective_neck_length_mm,
                                     n * (np.asarray(cavity_length_mm, dtype=float) + wall_extra_length_mm),
                                     np.asarray(side_volume_mm3, dtype=float) / (cavity_area * n), cone)
    return _c_mm_s(speed_of_sound_m_s) * k / (2.0 * np.pi)


def soft_wall_length_scale(shear_modulus_pa, cavity_diameter_mm, cap_outer_diameter_mm):
    """Quasi-static silicone-wall compliance as (n, ΔL) for :func:`transmission_line_hz`.

    Assumptions (all stated, none hidden): incompressible linear-elastic silicone of shear modulus G; the
    cylindrical wall deforms as a Lamé thick cylinder in plane strain with inner radius a and outer radius b
    (ΔS/S = p/G · b²/(b² − a²)); the closed end deforms like a half-space loaded on a disc of radius a
    (w̄ = 0.4244 p a/G); the acrylic neck is rigid; wall inertia is neglected, so the model holds only well
    below the cap's wall modes (≥ 3× f): above them the wall is mass-like and the true shift has the opposite
    sign. The infinite tube also overstates a real cap's compliance (bonded base, clamped flange, finite top:
    about 1.4× for the paper's cap against the coupled FEM).

    The wall slows waves in the cavity (Korteweg): n² = 1 + (ρc²/G)·b²/(b² − a²); the end compliance is an
    extra closed length ΔL = 0.4244·a·ρc²/(G·n²) (mm). Both → rigid (n = 1, ΔL = 0) as G → ∞.
    """
    g = np.asarray(shear_modulus_pa, dtype=float)
    a = np.asarray(cavity_diameter_mm, dtype=float) / 2.0
    b = np.asarray(cap_outer_diameter_mm, dtype=float) / 2.0
    stiffness_ratio = BULK_MODULUS_PA / g
    n2 = 1.0 + stiffness_ratio * b * b / (b * b - a * a)
    extra = HALF_SPACE_MEAN_DISPLACEMENT * a * stiffness_ratio / n2
    with np.errstate(invalid="ignore"):  # a sweep's impossible variant (cap inside the cavity, b < a): NaN
        return np.sqrt(n2), extra


def wall_breathing_hz(shear_modulus_pa, density_kg_m3, cavity_diameter_mm, cap_outer_diameter_mm):
    """In-vacuo breathing resonance of an incompressible thick cylinder wall (Hz).

    Lamé stiffness 4πG(b² − a²)/b² per unit length against the radial-flow kinetic mass
    2πρ a² ln(b/a): ω² = 2G(1 − a²/b²) / (ρ a² ln(b/a)), exact for the radial mode u_r ∝ 1/r of an
    incompressible plane-strain tube (the closed form the coupled FEM's elastic operator is tested against).
    """
    a = np.asarray(cavity_diameter_mm, dtype=float) / 2.0 / MM_PER_M
    b = np.asarray(cap_outer_diameter_mm, dtype=float) / 2.0 / MM_PER_M
    omega2 = 2.0 * shear_modulus_pa * (1.0 - a * a / (b * b)) / (density_kg_m3 * a * a * np.log(b / a))
    return np.sqrt(omega2) / (2.0 * np.pi)
