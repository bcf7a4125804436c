"""First-use friction: init, --set, plausibility notes, distinct options, completion, report.json rebuilds the kit
byte for byte, templates and docs in the wheel."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
import zipfile

import pytest

from matcad import spec as spec_mod
from matcad.prediction import predict
from matcad.build import build
from matcad.spec import frequency_notes, spec_notes
from tests.conftest import MINIMAL, PAPER, ROOT, missing_client, run_cli

LASER_ONLY = ROOT / "templates" / "mat-laser-only.toml"


def test_set_overrides_like_an_edited_file(write_spec):
    code, out, err = run_cli("predict", PAPER, "--json", "--set", "neck.diameter=1.8", "--set", "wall.model=rigid")
    assert code == 0, err
    data = spec_mod.read_spec_data(PAPER)  # the file as written: its [calibration] then belongs to the edited neck
    data["neck"]["diameter"], data["wall"]["model"] = 1.8, "rigid"
    assert json.loads(out)["f0_hz"] == pytest.approx(predict(spec_mod.from_dict(data)).f0_hz, rel=1e-12)
    code, _, err = run_cli("check", PAPER, "--set", "neck.diameter=-2")
    assert code == 2 and "neck.diameter" in err and "-2" in err
    code, _, err = run_cli("predict", PAPER, "--set", "neck.diametr=2")
    assert code == 2 and "did you mean 'diameter'" in err
    code, _, err = run_cli("predict", PAPER, "--set", "nonsense")
    assert code == 2 and "KEY=VALUE" in err


def test_init_copies_a_template_and_never_overwrites(tmp_path):
    code, _, err = run_cli("init", "my-taxel", "--from", "mat-laser-only", cwd=tmp_path)
    assert code == 0, err
    spec = spec_mod.load(tmp_path / "my-taxel.toml")
    assert spec.name == "my-taxel" and spec.outputs.assembly is False
    assert "# D: paper Sec. II" in (tmp_path / "my-taxel.toml").read_text()  # sources kept
    before = (tmp_path / "my-taxel.toml").read_bytes()
    code, _, err = run_cli("init", "my-taxel", cwd=tmp_path)
    assert code == 2 and "refusing" in err and (tmp_path / "my-taxel.toml").read_bytes() == before
    code, _, err = run_cli("init", "x", "--from", "nope", cwd=tmp_path)
    assert code == 2 and "mat-paper" in err and not (tmp_path / "x.toml").exists()
    code, _, err = run_cli("init", "../escape", cwd=tmp_path)
    assert code == 2 and "name" in err and not (tmp_path.parent / "escape.toml").exists()


@pytest.mark.parametrize("key, value, meant", [
    ("air.temperature_c", 293.0, "19.85"), ("needle.theta_deg", 1.309, "75"),
    ("microphone.sample_rate_hz", 44.1, "44100")])
def test_unit_slips_get_the_value_they_meant(key, value, meant):
    section, name = key.split(".")
    data = spec_mod.to_dict(spec_mod.load(PAPER))
    assert spec_notes(spec_mod.from_dict(data), data) == []
    data[section][name] = value
    notes = spec_notes(spec_mod.from_dict(data), data)
    assert len(notes) == 1 and key in notes[0] and meant in notes[0]


def test_kpa_metres_khz_and_rigid_default():
    data = spec_mod.to_dict(spec_mod.load(PAPER))
    data["wall"]["shear_modulus_mpa"] = [200.0, 600.0]
    (note,) = spec_notes(spec_mod.from_dict(data), data)
    assert "[0.2, 0.6]" in note
    import tomllib

    minimal = tomllib.loads(MINIMAL)
    (note,) = spec_notes(spec_mod.from_dict(minimal), minimal)
    assert "rigid" in note and "[wall]" in note
    metres = {"name": "m", "cavity": {"diameter": 0.01, "length": 0.02}, "neck": {"diameter": 0.005, "length": 0.01}}
    notes = spec_notes(spec_mod.from_dict(metres), metres)
    assert any("metres" in n and "cavity.diameter = 10" in n for n in notes)
    assert "4700 Hz" in frequency_notes([4.0, 4.3, 4.7])[0] and frequency_notes([4000.0, 4700.0]) == []


@pytest.mark.parametrize("key, value, reading", [
    ("wall.shear_modulus_mpa", [1e6, 1e6], "[1000, 1000] MPa, outside 0.001-50 MPa"),
    ("wall.shear_modulus_mpa", [0.001, 1e6], "[1e-06, 1000] MPa, outside 0.001-50 MPa"),
    ("wall.shear_modulus_mpa", [0.2, 60.0], "[0.0002, 0.06] MPa, outside 0.001-50 MPa"),
    ("air.temperature_c", 1000.0, "726.9 °C, above 150 °C"),
    ("needle.theta_deg", 0.01, "0.573°, almost flat"),
    ("microphone.sample_rate_hz", 0.1, "100 Hz, below 400 Hz")])
def test_a_unit_slip_note_suggests_only_a_plausible_value(key, value, reading):
    """wall.shear_modulus_mpa = 1e6 got "kPa entered? did you mean [1000, 1000]?" (still 1000 MPa) and
    [0.001, 1e6] got [1e-06, 1000] (below the 1 kPa minimum): where the other unit's reading is no likelier, the
    note says what is implausible about both and suggests nothing. A kHz-slip note on frequencies suggests no value
    below 100 Hz (which would draw the note itself)."""
    section, name = key.split(".")
    data = spec_mod.to_dict(spec_mod.load(PAPER))
    data[section][name] = value
    (note,) = spec_notes(spec_mod.from_dict(data), data)
    assert key in note and f"it would be {reading} as well" in note and "did you mean" not in note, note
    assert frequency_notes([0.05, 0.09]) == [] and "100 Hz" in frequency_notes([0.1])[0]


def test_option_names_are_distinct_and_fem_level_needs_fem():
    code, new, _ = run_cli("predict", PAPER, "--json", "--load", "0", "10")
    code_old, old, err = run_cli("predict", PAPER, "--json", "--force", "0", "10")
    assert code == code_old == 0 and json.loads(new)["load_curve"] == json.loads(old)["load_curve"]
    assert "deprecated" in err
    code, _, err = run_cli("predict", PAPER, "--fem-level", "4")
    assert code == 2 and "--model fem" in err


def test_bash_completion_completes_commands_and_options():
    bash = shutil.which("bash")
    if bash is None:
        missing_client("bash missing", "install bash: the completion script is bash's", ".ci/run runs under bash")
    code, script, _ = run_cli("completion", "bash")
    assert code == 0

    def complete(*words):
        probe = (f"{script}\nCOMP_WORDS=(matcad {' '.join(words)}); COMP_CWORD={len(words)}; "
                 "_matcad_complete; printf '%s\\n' \"${COMPREPLY[@]}\"")
        return subprocess.run([bash, "-c", probe], capture_output=True, text=True, check=True).stdout.split()

    assert complete("bu") == ["build"]
    assert set(complete("")) >= {"predict", "build", "check", "serve", "init", "completion", "schema"}
    assert complete("build", "x.toml", "--s") == ["--set"]
    assert "--load" in complete("predict", "x.toml", "--")


def test_report_json_rebuilds_the_kit_byte_for_byte(tmp_path):
    first = build(spec_mod.load(PAPER), tmp_path / "a").out_dir
    code, _, err = run_cli("build", first / "report.json", "--out", tmp_path / "b")
    assert code == 0, err
    names = sorted(p.name for p in first.iterdir())
    assert names == sorted(p.name for p in (tmp_path / "b").iterdir()) and len(names) > 20
    for name in names:
        a, b = ((d / name).read_bytes() for d in (first, tmp_path / "b"))
        assert hashlib.sha256(a).hexdigest() == hashlib.sha256(b).hexdigest(), name


@pytest.mark.slow
def test_wheel_ships_templates_docs_page_and_license(tmp_path):
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                    str(tmp_path), str(ROOT)], check=True, capture_output=True)
    (wheel,) = tmp_path.glob("matcad-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for template in (ROOT / "templates").glob("*.toml"):
        assert f"matcad/templates/{template.name}" in names
    for doc in ("physics.md", "paper.md", "api.md"):
        assert f"matcad/docs/{doc}" in names
    assert {"matcad/web/design.html", "matcad/web/design.js", "matcad/web/viewer.js"} <= names  # the page inlines both
    assert any(n.endswith("LICENSE") for n in names)
