"""Taxel bands: unloaded band + loaded rise (Eq. 5 or the cap mechanics), the guard, overlap and harmonic checks."""

import dataclasses
import sys
import tomllib

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.prediction import bands
from matcad.prediction import curves as curve_cache
from matcad.listening import guard_hz
from matcad.prediction.bands import TaxelBand, conflicts, taxel_band
from matcad.acoustics.design import calibration
from matcad.prediction import predict
from matcad.spec import SpecError
from tests.conftest import FAST_MECHANICS, MINIMAL, PAPER

FAST = FAST_MECHANICS + "max_force_n = 6.0\n"


def _band(name, lo, hi):
    return TaxelBand(name, (lo + hi) / 2, (lo, hi), (lo, hi), "transmission_line", 20.0, 1.0, "test")


def test_calibrated_band_is_the_predicted_band_raised_by_eq5():
    s = spec_mod.load(PAPER)
    b = taxel_band(s)
    p = predict(s)
    cal = calibration(s)
    f = cal.frequency_hz([0.0, s.mechanics.max_force_n])
    assert b.f0_hz == p.f0_hz and b.unloaded_hz == p.band_hz
    assert b.rise == pytest.approx(f[1] / f[0], rel=1e-12)
    assert b.loaded_hz == (pytest.approx(p.band_hz[0]), pytest.approx(p.band_hz[1] * f[1] / f[0]))
    assert "Eq. 5" in b.rise_source and b.rise > 1.05  # the paper's taxel rises ~10 % by 20 N


def test_max_force_past_the_eq5_minimum_names_the_field():
    s = spec_mod.load(PAPER)
    s = dataclasses.replace(s, mechanics=dataclasses.replace(s.mechanics, max_force_n=30.0))
    with pytest.raises(SpecError) as err:
        taxel_band(s)
    assert err.value.field == "mechanics.max_force_n" and "26.9" in str(err.value)
    with pytest.raises(SpecError):
        spec_mod.from_dict({"name": "x", "cavity": {"diameter": 3, "length": 4}, "neck": {"diameter": 2, "length": 6},
                            "mechanics": {"max_force_n": -1}})


def test_cheap_path_without_calibration_skips_felupe():
    s = spec_mod.from_dict(tomllib.loads(MINIMAL))
    b = taxel_band(s, mechanics=False)
    assert b.loaded_hz == b.unloaded_hz and b.rise == 1.0 and "not computed" in b.rise_source


def test_mechanics_rise_once_per_cap_and_equal_to_predict_load(monkeypatch):
    """Two taxels with the same cap and different necks: one FElupe run; the rise equals `predict --load`'s."""
    from matcad.mechanics import solver

    calls = []
    real = solver.cap_curve
    monkeypatch.setattr(solver, "cap_curve", lambda s, progress=None: calls.append(1) or real(s, progress))
    monkeypatch.setattr(curve_cache, "_CAP_CURVES", {})
    s = spec_mod.from_dict(tomllib.loads(FAST))
    wide = dataclasses.replace(s, neck=dataclasses.replace(s.neck, diameter=2.6))
    b1, b2 = taxel_band(s), taxel_band(wide)
    assert len(calls) == 1 and b2.f0_hz > b1.f0_hz * 1.1
    p = predict(s, forces_n=[s.mechanics.max_force_n])
    f_max = next(q.f_hz for q in p.load_curve if q.source.startswith("cap mechanics"))
    assert b1.rise == pytest.approx(f_max / p.f0_hz, rel=1e-9)  # f rises monotonically on this cap to 6 N
    assert b1.loaded_hz[1] == pytest.approx(b1.unloaded_hz[1] * f_max / p.f0_hz, rel=1e-9)
    assert 1.01 < b1.rise < 1.5


def test_max_force_beyond_the_mechanics_curve_names_the_field(monkeypatch):
    s = spec_mod.from_dict(tomllib.loads(FAST.replace("max_force_n = 6.0", "max_force_n = 500.0")))
    with pytest.raises(SpecError) as err:
        taxel_band(s)
    assert err.value.field == "mechanics.max_force_n" and "displacement_mm" in str(err.value)


def test_guard_follows_the_trackers_bins():
    from matcad.listening import EDGE_BINS, EXCLUDE_BINS
    from matcad.loop.spectrum import Framer

    for fs in (44100.0, 48000.0, 96000.0):
        df = np.diff(Framer(fs).freqs[:2])[0]
        assert guard_hz(fs) == pytest.approx((EXCLUDE_BINS + EDGE_BINS) * df)
    assert guard_hz(44100.0) == pytest.approx(43.07, abs=0.01)


def test_conflicts_overlap_guard_and_harmonics():
    g = 40.0
    assert conflicts([_band("a", 4000, 4400), _band("b", 4441, 4900)], g) == []
    (c,) = conflicts([_band("a", 4000, 4400), _band("b", 4420, 4900)], g)
    assert (c.taxel, c.other, c.harmonic, c.gap_hz) == ("a", "b", 1, pytest.approx(20.0))
    (c,) = conflicts([_band("a", 4000, 4500), _band("b", 4400, 4900)], g)
    assert c.gap_hz == pytest.approx(-100.0) and "overlap by 100 Hz" in c.describe()
    # 2 x [3000, 3100] = [6000, 6200] lands in b's band; 3 x [2000, 2100] = [6000, 6300] too
    found = conflicts([_band("a", 3000, 3100), _band("b", 6100, 6500), _band("c", 2000, 2100)], g)
    assert {(c.taxel, c.harmonic, c.other) for c in found} == {("a", 2, "b"), ("c", 3, "b")}
    hit = next(c for c in found if c.taxel == "a")
    assert hit.band_hz == (6000, 6200) and hit.gap_hz == pytest.approx(-100.0)
    assert "a's harmonic 2f" in hit.describe() and "b's loaded band" in hit.describe()


def test_bands_module_does_not_import_felupe_on_the_cheap_path():
    import subprocess

    code = ("import sys; from matcad import spec; from matcad.prediction.bands import taxel_band; "
            "s = spec.load(%r); taxel_band(s); taxel_band(s, mechanics=False); "
            "assert 'felupe' not in sys.modules and 'skfem' not in sys.modules" % str(PAPER))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


BOARD = MINIMAL.replace('name = "t"', 'name = "board"') + """[guide]
thickness_measured = true
[mechanics]
max_force_n = 5.0
[calibration]
v0_mm3 = 32.21
a = -0.0086
b = 0.4626
area_convention = "d2/4"
"""


def test_identical_taxels_overlap_and_check_names_both(write_spec):
    from matcad.rules import check
    from tests.conftest import run_cli

    s = spec_mod.from_dict(tomllib.loads(BOARD + "[array]\ncolumns = 2\npitch_x = 14.0\n"))
    b1, b2 = bands.taxel_bands(s)
    assert (b1.name, b1.x_mm, b2.name, b2.x_mm) == ("t1", -7.0, "t2", 7.0) and b1.loaded_hz == b2.loaded_hz
    (f,) = [f for f in check(s) if f.id == "bands.overlap"]
    width = b1.loaded_hz[1] - b1.loaded_hz[0]
    assert f.level == "error" and f.value == pytest.approx(-width, abs=0.1)
    assert "t1's loaded band" in f.message and "t2's loaded band" in f.message and f"overlap by {width:.0f} Hz" in f.message
    code, out, _ = run_cli("check", write_spec(BOARD + "[array]\ncolumns = 2\npitch_x = 14.0\n"))
    assert code == 1 and "bands.overlap" in out


def test_a_taxel_at_twice_anothers_f0_is_warned_about_its_harmonic():
    from matcad.design.solve import parse_vary, solve
    from matcad.rules import check

    one = spec_mod.from_dict(tomllib.loads(BOARD))
    low = solve(one, 2400.0, parse_vary(one, ["cavity.length"])).spec.cavity.length
    high = solve(one, 4800.0, parse_vary(one, ["neck.diameter"])).spec.neck.diameter
    s = spec_mod.from_dict(tomllib.loads(
        BOARD + f"[[taxel]]\nx = -7.0\ny = 0.0\ncavity_length = {low!r}\n"
                f"[[taxel]]\nx = 7.0\ny = 0.0\nneck_diameter = {high!r}\n"))
    b1, b2 = bands.taxel_bands(s)
    assert b1.f0_hz == pytest.approx(2400.0, rel=1e-6) and b2.f0_hz == pytest.approx(4800.0, rel=1e-6)
    assert b1.loaded_hz[1] < b2.loaded_hz[0]  # disjoint themselves
    # issue 24: a harmonic in another band is tracked around (matcad.loop.board.discount_harmonics): a warning
    assert not [f for f in check(s) if f.id.startswith("bands.") and f.level == "error"]
    (f,) = [f for f in check(s) if f.id.startswith("bands.") and f.level == "warning"]
    assert f.id == "bands.harmonic" and "t1's harmonic 2f" in f.message and "t2's loaded band" in f.message
    assert f.value == pytest.approx(max(2 * b1.loaded_hz[0], b2.loaded_hz[0]) - min(2 * b1.loaded_hz[1], b2.loaded_hz[1]),
                                    abs=0.05)  # rounded to 0.1 Hz


def test_single_taxel_build_bands_never_fail_on_the_rise():
    from matcad.build import board_bands

    s = spec_mod.load(PAPER)
    s = dataclasses.replace(s, mechanics=dataclasses.replace(s.mechanics, max_force_n=30.0))
    (t,) = board_bands(s)["taxels"]
    assert t["rise"] == 1.0 and "not computed" in t["rise_source"] and "mechanics.max_force_n" in t["rise_source"]
    assert t["loaded_hz"] == t["unloaded_hz"]


def test_build_writes_the_band_chart_and_its_numbers(tmp_path):
    import json

    from matcad.build import build

    s = spec_mod.load(PAPER)
    s = dataclasses.replace(s, outputs=dataclasses.replace(s.outputs, end_cap_mold=False, needle_mount=False,
                                                           assembly=False))
    build(s, tmp_path / "kit")
    report = json.loads((tmp_path / "kit" / "report.json").read_text())
    (row,) = report["bands"]["taxels"]
    band = taxel_band(s)
    assert row["model"] == "calibration" and row["f0_hz"] == pytest.approx(4010.4, abs=0.1)  # the anchored band
    assert row["loaded_hz"] == pytest.approx(list(band.loaded_hz)) and row["rise"] == pytest.approx(band.rise)
    assert report["bands"]["guard_hz"] == pytest.approx(guard_hz(s.microphone.sample_rate_hz))
    png = tmp_path / "kit" / "plot_taxel_bands.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "plot_taxel_bands.png" in [f["file"] for f in report["figures"]]
    md = (tmp_path / "kit" / "report.md").read_text()
    assert f"| t1 | 0, 0 | {band.f0_hz:.0f} | {band.unloaded_hz[0]:.0f}–{band.unloaded_hz[1]:.0f} | " \
           f"{band.loaded_hz[0]:.0f}–{band.loaded_hz[1]:.0f} |" in md
    assert "(plot_taxel_bands.png)" in md and "plot_taxel_bands.png" in (tmp_path / "kit" / "report.html").read_text()
