"""The part and model registries: adding a part is one module with one entry; every flag has a part and every
part a flag; every registered part of the paper template renders and reads back at its dimensions; the
acoustic models and material laws are listed once."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import textwrap

import pytest

import matcad.parts
from matcad.parts import registry
from matcad.parts.registry import NON_PART_FLAGS, Kind, Part, PrintPose
from matcad.spec import Outputs
from matcad.spec import load as load_spec
from tests.conftest import PAPER, ROOT
from tests.readback import assert_build_folder, assert_laser_files

LASER_ONLY = ROOT / "templates" / "mat-laser-only.toml"

WIDGET = '''
"""A test part: a 12 x 7 mm tag with one 3 mm hole, cut from the guide sheet."""
from matcad.parts.features import sheet_kerf_mm
from matcad.parts.flat import Flat, Hole
from matcad.parts.registry import Kind, Part


def tag(spec) -> Flat:
    return Flat(name="test_tag", thickness=spec.guide.thickness, thickness_measured=False,
                kerf=sheet_kerf_mm(spec, "guide"), width=12.0, depth=7.0, holes=(Hole(0.0, 0.0, 3.0, "tag"),))


PARTS = (Part("test_tag", Kind.LASER, flag="guides", make=tag, order=35, colour="#123456", sheet="guide"),)
'''

PRINTED_WIDGET = '''
"""A printed-only test part: a 10 x 6 x 4 mm block (the CAD kernel imported inside make)."""
from matcad.parts.registry import Kind, Part, PrintPose


def block(spec):
    from build123d import Align, Box

    return Box(10.0, 6.0, 4.0, align=(Align.CENTER, Align.CENTER, Align.MIN))


PARTS = (Part("test_block", Kind.PRINTED, flag="guides", make=block, order=90, colour="#654321",
              pose=PrintPose(0.0, "flat underside"), extent=lambda spec: (10.0, 6.0, 4.0)),)
'''


@pytest.fixture
def extra_part(tmp_path, monkeypatch):
    """Drop one module into matcad.parts (a folder added to its path) and rediscover; undone afterwards."""
    def _add(source: str, module: str):
        folder = tmp_path / "extra_parts"
        folder.mkdir(exist_ok=True)
        (folder / f"{module}.py").write_text(textwrap.dedent(source), encoding="utf-8")
        monkeypatch.setattr(matcad.parts, "__path__", [*matcad.parts.__path__, str(folder)])
        monkeypatch.delitem(sys.modules, f"matcad.parts.{module}", raising=False)
        registry.parts.cache_clear()
    yield _add
    registry.parts.cache_clear()


def _without_other_outputs(spec, keep: str):
    flags = {f.name: False for f in dataclasses.fields(Outputs) if f.name not in ("reference_square", keep)}
    return dataclasses.replace(spec, outputs=dataclasses.replace(spec.outputs, **flags))


def test_every_outputs_flag_has_a_part_and_every_part_a_flag():
    flags = {f.name for f in dataclasses.fields(Outputs)}
    used = {p.flag for p in registry.parts()}
    assert set(NON_PART_FLAGS) <= flags and not used & set(NON_PART_FLAGS)
    assert used == flags - set(NON_PART_FLAGS)


def test_registered_parts_are_unique_ordered_and_name_their_files():
    from matcad.spec import Riser

    spec = load_spec(PAPER)
    spec = dataclasses.replace(spec, riser=Riser(thickness=1.5))  # a condition of every part holds: each is made
    assert all(p.when is None or p.when(spec) for p in registry.parts())
    names = [p.name for p in registry.parts()]
    assert len(names) == len(set(names))
    kinds = [p.kind for p in registry.parts()]
    assert kinds.index(Kind.LASER) < kinds.index(Kind.CAST) and Kind.LASER not in kinds[kinds.index(Kind.CAST):]
    for p in registry.parts():
        if p.kind is Kind.LASER:
            assert p.make(spec).name == p.name  # the Flat's name is the file stem the registry promises


def test_a_bad_entry_is_refused_at_registration():
    with pytest.raises(TypeError):  # colour is required: no silent KeyError later in the section
        Part("x", Kind.LASER, flag="guides", make=print, order=1, sheet="guide")
    with pytest.raises(ValueError, match="colour 'red' invalid"):
        Part("x", Kind.LASER, flag="guides", make=print, order=1, colour="red", sheet="guide")
    with pytest.raises(ValueError, match="flag 'stickers' invalid"):
        Part("x", Kind.LASER, flag="stickers", make=print, order=1, colour="#000000", sheet="guide")
    with pytest.raises(ValueError, match="pose must be given"):
        Part("x", Kind.PRINTED, flag="guides", make=print, order=1, colour="#000000", extent=print)
    with pytest.raises(ValueError, match="extent must be given"):
        Part("x", Kind.PRINTED, flag="guides", make=print, order=1, colour="#000000", pose=PrintPose(0.0, "flat"))


def test_registering_imports_no_cad_kernel():
    code = ("import sys; from matcad.parts.registry import parts; from matcad.parts.catalogue import laser_parts; "
            "assert len(parts()) >= 8; bad = [m for m in ('build123d', 'OCP', 'trimesh') if m in sys.modules]; "
            "assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_a_new_part_is_one_module_and_is_built_exported_and_reported(extra_part, tmp_path):
    from matcad.build import build
    from matcad.parts.catalogue import needs_cad_kernel

    extra_part(WIDGET, "test_widget")
    spec = load_spec(LASER_ONLY)
    assert not needs_cad_kernel(spec)
    result = build(spec, tmp_path / "out")
    assert {"test_tag.dxf", "test_tag.svg", "preview_test_tag.png"} <= set(result.files)
    assert_laser_files(spec, result.out_dir)  # the tag's DXF read back: hole drawn 3 - kerf, outline 12 + kerf
    report = json.loads((result.out_dir / "report.json").read_text())
    assert {"test_tag.dxf", "test_tag.svg"} <= {f["file"] for f in report["files"]}
    holes = [h for h in report["as_built"]["laser_holes"] if h["part"] == "test_tag"]
    assert [(h["purpose"], h["finished_mm"]) for h in holes] == [("tag", 3.0)]
    cuts = [s for s in report["fabrication"]["steps"] if "test_tag.dxf" in s["files"]]
    assert cuts and "guide_clamp.dxf" in cuts[0]["files"]  # cut from the guide sheet with the guides
    assert any("test_tag" in row for s in report["bom"]["sheets"] for row in s["parts"])


def test_a_printed_only_part_loads_the_kernel_without_other_edits(extra_part, tmp_path):
    import trimesh

    from matcad.build import build
    from matcad.parts.catalogue import needs_cad_kernel

    extra_part(PRINTED_WIDGET, "test_printed_widget")
    spec = _without_other_outputs(load_spec(PAPER), "guides")
    spec = dataclasses.replace(spec, outputs=dataclasses.replace(spec.outputs, guides=True))
    assert needs_cad_kernel(spec)
    result = build(spec, tmp_path / "out", force=True)
    assert {"test_block.stl", "test_block.step"} <= set(result.files)
    mesh = trimesh.load_mesh(result.out_dir / "test_block.stl")
    assert mesh.is_watertight and mesh.volume == pytest.approx(240.0, rel=1e-6)
    assert mesh.extents == pytest.approx([10.0, 6.0, 4.0], abs=1e-6) and mesh.bounds[0][2] == pytest.approx(0.0)
    report = json.loads((result.out_dir / "report.json").read_text())
    assert report["meshes"]["test_block.stl"]["bed_face"] == "flat underside"
    printing = [s for s in report["fabrication"]["steps"] if s["where"].startswith("printer")]
    assert printing and printing[0]["files"] == ["print_fdm.3mf", "test_block.stl"]
    import zipfile  # the print job carries the new part too, with the default profile

    with zipfile.ZipFile(result.out_dir / "print_fdm.3mf") as job:
        assert 'name="test_block"' in job.read("3D/3dmodel.model").decode()
        assert 'key="perimeters" value="3"' in job.read("Metadata/Slic3r_PE_model.config").decode()


@pytest.fixture(scope="module")
def paper_build(tmp_path_factory):
    from matcad.build import build

    spec = load_spec(PAPER)
    return spec, build(spec, tmp_path_factory.mktemp("paper") / "out")


def test_every_registered_part_of_the_paper_template_renders_and_reads_back(paper_build):
    """boxes.py style: every registered part the template asks for is written, and each file reads back at the
    dimensions its part function made (laser: drawn holes and outline with kerf; 3-D: the STL's extents and
    volume equal the B-rep's in its print pose)."""
    import trimesh

    from matcad.parts.catalogue import in_print_pose

    spec, result = paper_build
    out = result.out_dir
    assert_build_folder(spec, out)
    wanted = registry.wanted(spec)
    assert spec.riser is None  # a riser is cut for a [riser] only: tests/test_riser.py builds one
    assert {p.name for p in wanted} == {p.name for p in registry.parts()} - {"riser"} - (
        set() if spec.spacer.style == "laser" else {"spacer"})
    for p in wanted:
        assert f"preview_{p.name}.png" in result.files
        if p.kind is Kind.LASER:
            assert {f"{p.name}.dxf", f"{p.name}.svg"} <= set(result.files)
            continue
        posed, _ = in_print_pose(p.name, p.make(spec))
        box = posed.bounding_box()
        mesh = trimesh.load_mesh(out / f"{p.name}.stl")
        assert mesh.bounds[0][2] == pytest.approx(0.0, abs=1e-6), p.name  # on the bed
        assert mesh.extents == pytest.approx([box.size.X, box.size.Y, box.size.Z], abs=0.02), p.name
        assert mesh.volume == pytest.approx(posed.volume, rel=2e-3), p.name
    svg = (out / "section.svg").read_text()
    for p in wanted:
        if f'id="{p.name}"' in svg:
            assert p.section_label in svg  # its label from the registry entry


def test_model_registry_is_the_one_list():
    from matcad.acoustics import registry as models
    from matcad.acoustics.registry import cheap_models, model_errors
    from matcad.commands import parser as build_parser

    parser = build_parser()
    predict = next(a for a in parser._subparsers._group_actions[0].choices["predict"]._actions
                   if "--model" in a.option_strings)
    assert list(predict.choices) == models.model_choices()
    assert cheap_models() == tuple(m.name for m in models.MODELS if not m.needs_skfem)
    assert [m.rung for m in models.MODELS] == sorted(m.rung for m in models.MODELS)
    assert set(models.model_names()) <= set(model_errors())  # each rung's measured error (fem: vs its extrapolation)
    for m in models.MODELS:
        assert callable(m.function()) and m.source


def test_registry_models_evaluate_their_closed_forms():
    """The registry's lumped rung is paper Eq. 1 (c_f = 0): f = c/(2π) sqrt(A/(V l)), evaluated independently."""
    import math

    from matcad.acoustics.design import design
    from matcad.acoustics.registry import model
    from matcad.acoustics.resonator import resonator

    res = resonator(design(load_spec(PAPER)))
    want = res.c_m_s * 1000 / (2 * math.pi) * math.sqrt(res.neck_area / (res.volume * res.neck_length))
    assert float(model("lumped").f0_hz(res)) == pytest.approx(want, rel=1e-12)
    with pytest.raises(ValueError, match="'fem' solves a mesh"):
        model("fem").f0_hz(res)  # a solver rung is not a closed form


def _half_lumped(res, shear_modulus_pa=None, loss_factor=0.0):
    """A made-up rung for the registration test: half of paper Eq. 1 (Hz)."""
    from matcad.acoustics import resonator

    return resonator.lumped_hz(res) / 2


def test_predict_takes_every_registered_model_or_says_why():
    """`predict --model M` for every registered model and derived choice, on a rigid and a silicone template:
    M's own f0 is the answer, or a ValueError that names why M does not apply."""
    from matcad.acoustics.registry import model_choices
    from matcad.prediction import predict

    reasons = {"soft_wall": "serves wall.model = 'silicone' only", "elastic_wall": "serves wall.model = 'silicone'",
               "relative": "needs a [reference] taxel", "calibration": "needs a [calibration] in the spec",
               "as_built": "needs [[measured]] taxels in the spec"}
    for spec in (load_spec(LASER_ONLY), load_spec(PAPER)):
        for name in model_choices():
            try:
                p = predict(spec, model=name, fem_level=2, mechanics=False)
            except ValueError as exc:
                assert name in reasons and reasons[name] in str(exc), (spec.wall.model, name, exc)
                continue
            assert p.model == name and p.f0_hz == p.models[name].f0_hz > 0
            assert p.band_hz[0] < p.f0_hz < p.band_hz[1]


def test_a_registered_model_is_predicted_and_offered_by_the_cli(monkeypatch, capsys):
    """Registering a rung is one entry: predict evaluates it, --model offers and picks it, its unmeasured error
    says so in the budget."""
    from matcad.acoustics import registry as models
    from matcad.cli import main
    from matcad.prediction import predict

    extra = models.AcousticModel("half_lumped", 7, ("rigid",), False, "tests.test_registry:_half_lumped",
                                 "half of paper Eq. 1 (a test rung)", ("neck_air_ratio_small",))
    monkeypatch.setattr(models, "MODELS", models.MODELS + (extra,))
    spec = load_spec(LASER_ONLY)
    p = predict(spec, model="half_lumped", mechanics=False)
    assert p.model == "half_lumped" and p.f0_hz == pytest.approx(p.models["lumped"].f0_hz / 2, rel=1e-12)
    assert p.models["half_lumped"].source == "half of paper Eq. 1 (a test rung)"
    assert any("error not measured yet" in b.tolerance for b in p.budget)
    assert main(["predict", str(LASER_ONLY), "--model", "half_lumped", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["model"] == "half_lumped"


def test_model_registry_imports_no_solver():
    code = ("import sys; from matcad.acoustics.registry import MODELS, model_choices; model_choices(); "
            "bad = [m for m in ('skfem', 'build123d', 'felupe') if m in sys.modules]; assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_material_laws_are_listed_once():
    from matcad.mechanics.material import MODELS
    from matcad.spec import Mechanics

    field = next(f for f in dataclasses.fields(Mechanics) if f.name == "material")
    assert tuple(field.metadata["choices"]) == MODELS
