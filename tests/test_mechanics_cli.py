"""`matcad predict --force` through the cap mechanics, as a user runs it."""

import json

import pytest

from tests.conftest import FAST_MECHANICS, run_cli

FAST = FAST_MECHANICS


def test_predict_force_without_calibration_uses_the_cap_mechanics(write_spec):
    code, out, err = run_cli("predict", write_spec(FAST), "--json", "--force", "0", "4", "8", "100")
    assert code == 0, err
    data = json.loads(out)
    curve = data["load_curve"]
    assert [p["force_n"] for p in curve] == [0.0, 4.0, 8.0, 100.0]
    assert all(set(p) >= {"force_n", "f_hz", "displacement_mm", "cavity_volume_mm3", "source"} for p in curve)
    assert all(p["source"].startswith("cap mechanics (neo_hookean, sticking, G = 0.3 MPa)") for p in curve)
    assert curve[0]["f_hz"] == pytest.approx(data["f0_hz"]) and curve[0]["displacement_mm"] == 0.0
    assert curve[0]["cavity_volume_mm3"] == pytest.approx(data["cavity_volume_mm3"], rel=1e-12)
    assert curve[0]["f_hz"] < curve[1]["f_hz"] < curve[2]["f_hz"]
    assert 0 < curve[1]["displacement_mm"] < curve[2]["displacement_mm"] <= 1.0
    assert curve[1]["cavity_volume_mm3"] > curve[2]["cavity_volume_mm3"]
    assert curve[3]["f_hz"] is None and "beyond the computed curve" in curve[3]["reason"]
    model = data["load_model"]
    assert model["complete"] and model["sensitivity_hz_per_n_at_0"] > 0
    assert model["eq5"]["area_convention"] == "pi_d2/4" and model["eq5"]["b"] > 0
    assert len(model["curve"]) == 5
    first, last = (model["curve"][i]["cavity_outline_mm"] for i in (0, -1))
    assert first[0] == [1.59, 0.0] and first[-1] == [0.0, 4.76]  # wall foot on the plate ... axis under the top
    assert last[0] == [1.59, 0.0] and last[-1][0] == 0.0 and last[-1][1] < 4.76  # the top moved down


def test_predict_force_table_names_each_source(write_spec):
    code, out, err = run_cli("predict", write_spec(FAST), "--force", "2")
    assert code == 0, err
    assert "load curve from cap mechanics" in out and "df/dF" in out and "Eq. 5 fit to it (d2/4)" in out


def test_bad_mechanics_travel_is_exit_2_naming_the_field(write_spec):
    code, out, err = run_cli("predict", write_spec(FAST.replace("displacement_mm = 1.0", "displacement_mm = 9.0")),
                             "--force", "1")
    assert code == 2 and out == "" and "Traceback" not in err
    assert "mechanics.displacement_mm" in err


def test_build_load_plot_path_stays_on_eq5_without_felupe():
    """The build's load plot asks predict for Eq. 5 only (mechanics=False): no cap mechanics, no FElupe import."""
    import subprocess
    import sys

    from tests.conftest import PAPER, ROOT

    code = ("import sys; from matcad import spec; from matcad.prediction import predict; "
            "from matcad.render.kit import load_forces_n; s = spec.load(%r); "
            "p = predict(s, forces_n=load_forces_n(s), mechanics=False); "
            "assert p.load_curve and all(q.source.startswith('calibration') for q in p.load_curve); "
            "assert p.load_model is None; assert 'felupe' not in sys.modules" % str(PAPER))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr


def test_predict_force_with_model_fem_takes_the_fem_route(write_spec):
    code, out, err = run_cli("predict", write_spec(FAST), "--json", "--force", "3", "--model", "fem",
                             "--fem-level", "3")
    assert code == 0, err
    data = json.loads(out)
    model = data["load_model"]
    assert model["route"] == "axisymmetric FEM on the deformed outline, level 3" and model["fem_note"] == ""
    assert all(s["f_fem_hz"] > 0 for s in model["curve"])
    assert model["curve"][0]["f_hz"] == pytest.approx(data["f0_hz"])
    assert data["load_curve"][0]["f_hz"] > data["f0_hz"]
