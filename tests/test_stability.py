"""Numerical stability over the extremes of the design space: finite or a clear error, monotone where physics
says so, continuous where matcad switches models, always the fundamental, soft wall → rigid smoothly."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from matcad import spec as spec_mod
from matcad.acoustics import fem, models
from matcad.acoustics.eq5 import MAT_PAPER_2024
from matcad.acoustics.design import design
from matcad.prediction import predict
from matcad.spec import SpecError

D, L, d, l = 3.18, 4.76, 2.10, 6.35


def _spec(scale=1.0, **over):
    data = {"name": "x", "cavity": {"diameter": D * scale, "length": L * scale},
            "neck": {"diameter": d * scale, "length": l * scale, "mouth": "baffled"}}
    for key, value in over.items():
        section, field = key.split("__")
        data.setdefault(section, {})[field] = value
    return spec_mod.from_dict(data)


def _all_finite(p):
    values = [p.f0_hz, *p.band_hz] + [m.f0_hz for m in p.models.values()] + [
        x for b in p.budget for x in (b.low_hz, b.high_hz)]
    return p.f0_hz > 0 and all(math.isfinite(v) for v in values)


@pytest.mark.parametrize("ratio", np.linspace(0.05, 1.0, 20))
def test_diameter_ratio_sweep_finite(ratio):
    p = predict(_spec(neck__diameter=D * ratio))
    assert _all_finite(p) and p.band_hz[0] < p.f0_hz < p.band_hz[1]


@pytest.mark.parametrize("neck_length", [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 50.0])
@pytest.mark.parametrize("scale", [0.2 / D, 1.0, 50.0 / D])
def test_neck_length_and_scale_sweep_finite(neck_length, scale):
    p = predict(_spec(scale=scale, neck__length=neck_length))
    assert _all_finite(p)


def test_monotone_in_neck_diameter_and_length_everywhere():
    ratios = np.linspace(0.05, 1.0, 200)
    f = [predict(_spec(neck__diameter=D * x)).f0_hz for x in ratios]
    assert np.all(np.diff(f) > 0)
    lengths = np.geomspace(0.1, 50.0, 100)
    f = [predict(_spec(neck__length=x)).f0_hz for x in lengths]
    assert np.all(np.diff(f) < 0)


def test_continuous_across_correction_switches():
    # Ingard's and the step correction are clipped at zero (ξ = 0.8 and ≈ 0.97): no jump in any model
    neck = D * np.linspace(0.7, 1.0, 30001)
    area, volume = np.pi * neck**2 / 4, np.pi * D**2 / 4 * L
    outer = models.baffled_end_correction_mm(neck / 2)
    ec = models.end_corrected_hz(343.0, area, volume, l + outer + models.ingard_end_correction_mm(neck, D))
    tl = models.transmission_line_hz(343.0, area, np.pi * D**2 / 4, l + outer + models.step_end_correction_mm(neck, D), L)
    for f in (ec, tl):
        assert np.all(np.isfinite(f))
        assert (np.abs(np.diff(f)) / f[:-1]).max() < 1e-4  # a 1e-5 step in d/D moves f by < 1e-4


@pytest.mark.parametrize("temperature", [-20.0, 0.0, 20.0, 40.0, 60.0])
def test_temperature_range(temperature):
    p = predict(_spec(air__temperature_c=temperature))
    assert _all_finite(p)
    colder = predict(_spec(air__temperature_c=temperature - 1))
    assert colder.f0_hz < p.f0_hz


def test_silicone_wall_finite_and_tends_to_rigid():
    shear_mpa = np.geomspace(1e-3, 1e5, 25)  # 1 kPa to effectively rigid
    specs = [_spec(wall__model="silicone", wall__shear_modulus_mpa=[g, g]) for g in shear_mpa]
    elastic = np.array([predict(s).f0_hz for s in specs])
    rigid = predict(_spec()).f0_hz
    assert np.all(np.isfinite(elastic)) and np.all(elastic > 0)
    assert elastic[-1] == pytest.approx(rigid, rel=1e-4)
    # the quasi-static (massless) wall: monotone, always below rigid, smooth
    static = np.array([predict(s).models["soft_wall"].f0_hz for s in specs])
    assert np.all(np.diff(static) > 0) and np.all(static < rigid * (1 + 1e-12))
    assert np.all(np.abs(np.diff(np.diff(np.log(static)))) < 0.2)


def test_forces_up_to_and_past_eq5_validity():
    cal = MAT_PAPER_2024.bound(343.0, d, l)
    forces = np.linspace(-5.0, 60.0, 651)
    f = cal.frequency_hz(forces)
    valid = forces <= cal.turn_force_n
    assert np.all(np.isfinite(f[valid])) and np.all(np.isnan(f[~valid]))
    assert np.all(np.diff(f[valid]) > 0)
    for force in forces[~valid][:: 50]:
        assert cal.invalid_reason(float(force))


def test_unphysical_extremes_are_clear_errors():
    for bad in ({"neck__diameter": D * 1.01}, {"cavity__length": 0.0}, {"air__temperature_c": -274.0},
                {"wall__shear_modulus_mpa": [0.0, 1.0]}, {"neck__length": float("inf")}):
        with pytest.raises(SpecError):
            _spec(**bad)


@given(r=st.floats(1e-6, 1.0), ln=st.floats(1e-3, 1e3), lc=st.floats(1e-3, 1e3))
@settings(max_examples=400, deadline=None)
def test_tline_root_is_the_fundamental_for_any_input(r, ln, lc):
    k = float(models.transmission_line_wavenumber(r, ln, lc))
    assert math.isfinite(k) and k > 0
    assert k * max(ln, lc) < math.pi / 2  # both tangents on their first branch: no overtone
    assert math.tan(k * ln) * math.tan(k * lc) == pytest.approx(r, rel=1e-8)


@pytest.mark.parametrize("ratio,neck_length", [(0.1, 6.35), (1.0, 6.35), (0.66, 0.3), (0.66, 30.0)])
def test_fem_and_tline_find_the_same_mode_at_extremes(ratio, neck_length):
    s = _spec(neck__diameter=D * ratio, neck__length=neck_length)
    tl = predict(s).models["transmission_line"].f0_hz
    run = fem.solve(fem.geometry(design(s)), 2 * math.pi * tl / 343.2e3, 4, 343.2)
    assert run.f0_hz == pytest.approx(tl, rel=0.05)
    assert run.cavity_energy_fraction > 0.3


@pytest.mark.parametrize("neck_diameter", [0.01, 0.05, 0.1])
def test_neck_thinner_than_its_tolerance_keeps_a_finite_budget(neck_diameter):
    p = predict(_spec(neck__diameter=neck_diameter))
    assert _all_finite(p) and p.band_hz[0] > 0
