"""The output contract: exit codes, nothing half-written, previous output kept, only what is asked is built."""

import json
import subprocess
import sys

import pytest

from matcad import spec as spec_mod
from matcad.build import build
from matcad.output import MANIFEST
from tests.conftest import MINIMAL, PAPER, ROOT, run_cli

LASER_ONLY = MINIMAL.replace('name = "t"', 'name = "laser"') + \
    "[outputs]\nend_cap_mold = false\nneedle_mount = false\nassembly = false\n"
BAD_RULE = MINIMAL + "[fasteners]\ndowel_fit_laser = \"press\"\n"


def _snapshot(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_build_then_rule_failure_leaves_previous_output(tmp_path, write_spec):
    out = tmp_path / "out" / "t"
    code, stdout, err = run_cli("build", write_spec(LASER_ONLY), "--out", out, "--json")
    assert code == 0, err
    assert set(json.loads(stdout)["written"]) >= {"neck_plate.dxf", "report.json"}
    before = _snapshot(tmp_path / "out")
    code, stdout, err = run_cli("build", write_spec(BAD_RULE), "--out", out)
    assert code == 1 and "fit.dowel_laser" in stdout and "nothing written" in err
    assert _snapshot(tmp_path / "out") == before
    # --force builds anyway and says so in the report
    code, _, err = run_cli("build", write_spec(BAD_RULE), "--out", out, "--force")
    assert code == 0, err
    assert json.loads((out / "report.json").read_text())["verdict"] == "fail"


def test_bad_spec_exit_2_and_out_untouched(tmp_path, write_spec):
    (tmp_path / "out").mkdir()
    code, out, err = run_cli("build", write_spec(MINIMAL.replace("2.1", "-2.1")), cwd=tmp_path)
    assert code == 2 and "neck.diameter" in err and "Traceback" not in err
    assert list((tmp_path / "out").iterdir()) == []


def test_crash_mid_build_keeps_previous_and_leaves_no_temp(tmp_path, monkeypatch):
    spec = spec_mod.from_dict({"name": "c", "cavity": {"diameter": 3.18, "length": 4.76},
                               "neck": {"diameter": 2.1, "length": 6.35},
                               "outputs": {"end_cap_mold": False, "needle_mount": False, "assembly": False}})
    out = tmp_path / "c"
    build(spec, out)
    before = _snapshot(tmp_path)
    import matcad.build as build_mod

    def explode(*args, **kwargs):
        raise RuntimeError("disk full")
    monkeypatch.setattr(build_mod, "write_svg", explode)
    with pytest.raises(RuntimeError):
        build(spec, out)
    assert _snapshot(tmp_path) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c"]


def test_refuses_to_replace_a_foreign_folder(tmp_path, write_spec):
    foreign = tmp_path / "thesis"
    foreign.mkdir()
    (foreign / "chapter1.tex").write_text("precious")
    code, _, err = run_cli("build", write_spec(LASER_ONLY), "--out", foreign)
    assert code == 2 and "refusing" in err
    assert (foreign / "chapter1.tex").read_text() == "precious" and len(list(foreign.iterdir())) == 1


def test_laser_only_build_never_imports_cad_kernel(tmp_path, write_spec):
    spec_path = write_spec(LASER_ONLY)
    code = ("import sys; from matcad.cli import main; rc = main(['build', %r, '--out', %r]); assert rc == 0; "
            "bad = [m for m in ('build123d', 'OCP', 'trimesh', 'manifold3d', 'felupe', 'matplotlib', 'ezdxf') "
            "if m in sys.modules]; "
            "assert not bad, bad" % (str(spec_path), str(tmp_path / "o")))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.suffix for p in (tmp_path / "o").iterdir() if p.name != MANIFEST) == (
        [".dxf"] * 7 + [".html", ".json", ".md", ".pdf"] + [".png"] * 6 + [".svg"] * 7 + [".zip"])
    # 4 parts and 3 nested sheets (plate, guide, spacer) as DXF and SVG, the 1:1 PDF; 6th png: the band chart


def test_check_exit_codes(write_spec):
    code, out, _ = run_cli("check", PAPER, "--json")
    data = json.loads(out)
    assert code == 0 and data["verdict"] == "pass"
    ids = {f["id"] for f in data["findings"]}
    assert "laser.taper" in ids  # the paper's 2.1 mm neck in 6.35 mm acrylic must warn about taper
    taper = next(f for f in data["findings"] if f["id"] == "laser.taper" and "neck hole" in f["message"])
    assert taper["level"] == "warning" and taper["value"] == pytest.approx(2.1 / 6.35, abs=1e-3)
    code, out, _ = run_cli("check", write_spec(BAD_RULE))
    assert code == 1 and "fit.dowel_laser" in out


def test_unwritable_output_is_exit_2(tmp_path, write_spec):
    blocker = tmp_path / "file"
    blocker.write_text("x")  # a folder cannot be made under a regular file, whoever runs this
    code, _, err = run_cli("build", write_spec(LASER_ONLY), "--out", blocker / "o")
    assert code == 2 and "Traceback" not in err and "matcad: error" in err
    assert blocker.read_text() == "x"
