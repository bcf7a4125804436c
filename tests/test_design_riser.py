"""`matcad design --vary neck.riser`: each taxel's neck through the [riser] or its cap in a pocket of it, the way
that needs the least change of the continuous fields; a board designed with it has both neck lengths, passes
`check`, and `predict` of each written taxel gives its target."""

import json
import math

import pytest

from matcad import spec as spec_mod
from matcad.design import Unreachable
from matcad.design.solve import CONTINUOUS, parse_vary, solve, with_fields
from matcad.prediction import predict
from matcad.rules import check, errors
from tests.conftest import ROOT, run_cli
from tests.test_design import ARRAY_BASE

LASER = ROOT / "templates" / "mat-laser-only.toml"
RISER = "[riser]\nthickness = {}\nthickness_measured = true\n"
THREE = ["neck.diameter", "cavity.diameter", "cavity.length"]
LOW_HZ = 1500.0
"""Below the 1604 Hz the laser-only taxel's 6.35 mm neck reaches with the three fields' default ranges (the route's
lowest f0); its neck through a 1.5 mm riser reaches 1454 Hz."""


def _laser_with_riser(write_spec, riser_mm=1.5):
    return write_spec(LASER.read_text(encoding="utf-8") + "\n" + RISER.format(riser_mm), "laser-riser.toml")


def _taxel_f0(spec) -> float:
    """f0 (Hz) of a single-taxel spec by `predict`, through the board API (its one taxel's own spec)."""
    return predict(spec_mod.taxel_spec(spec, spec_mod.taxels(spec)[0]), mechanics=False).f0_hz


def _log_distance(start, solved) -> float:
    """How far the continuous fields moved (the solver's |t|: Euclidean in ln x)."""
    return math.sqrt(sum(math.log(getattr(getattr(solved, s), n) / getattr(getattr(start, s), n)) ** 2
                         for s, n in (f.split(".") for f in CONTINUOUS)))


def test_a_target_below_the_plate_gets_the_long_neck(write_spec):
    s = spec_mod.load(_laser_with_riser(write_spec))
    with pytest.raises(Unreachable, match=r"reaches 1604-"):
        solve(s, LOW_HZ, parse_vary(s, THREE))
    r = solve(s, LOW_HZ, parse_vary(s, [*THREE, "neck.riser"]))
    assert r.spec.neck.riser and r.fields["neck.riser"] == (False, True)
    assert spec_mod.neck_length_mm(r.spec) == pytest.approx(7.85)
    assert _taxel_f0(r.spec) == pytest.approx(LOW_HZ, rel=0.005)
    assert not errors(check(r.spec))
    assert "neck through the riser, neck 7.85 mm" in r.to_text()


@pytest.mark.parametrize("target", [2500.0, 4000.0, 4800.0, 5400.0])
def test_the_way_kept_is_the_least_change(write_spec, target):
    """Both ways reach these targets; the kept one moves the continuous fields least (in ln x), and is the
    solution of that way alone: low targets take the long neck, high ones the pocket."""
    s = spec_mod.load(_laser_with_riser(write_spec))
    ways = {way: solve(with_fields(s, {"neck.riser": way}), target, parse_vary(s, THREE)) for way in (False, True)}
    moved = {way: _log_distance(s, r.spec) for way, r in ways.items()}
    r = solve(s, target, parse_vary(s, [*THREE, "neck.riser"]))
    kept = min(moved, key=moved.get)
    assert r.spec.neck.riser is kept and r.spec == ways[kept].spec
    assert kept is (target < 4900.0)
    assert _taxel_f0(r.spec) == pytest.approx(target, rel=0.005)


def test_discrete_fields_alone_take_the_nearest_f0(write_spec):
    """neck.riser alone (and with the plate's stock sheet): the choice whose f0 is nearest the target."""
    s = spec_mod.load(_laser_with_riser(write_spec))
    pocket, through = (_taxel_f0(with_fields(s, {"neck.riser": way})) for way in (False, True))
    for target in (through * 1.02, pocket * 0.98):
        r = solve(s, target, parse_vary(s, ["neck.riser"]))
        assert r.spec.neck.riser is (target < math.sqrt(pocket * through)) and "two lengths" in r.notes[0]
    both = solve(s, 4300.0, parse_vary(s, ["neck.length", "neck.riser"]))
    assert abs(both.error) < abs(solve(s, 4300.0, parse_vary(s, ["neck.length"])).error)
    assert _taxel_f0(both.spec) == both.f0_hz


def test_a_board_has_both_neck_lengths_and_passes_check(tmp_path, write_spec):
    """`design --taxels 4 --vary neck.diameter neck.riser` on a calibrated taxel with a 3 mm riser: the low bands
    take the long neck, the high ones pockets (the least change of the neck from 2.1 mm each); the written board
    passes `check`, each taxel's `predict` is its target, and the file reads back to the same spec."""
    base = write_spec(ARRAY_BASE.format(force="5.0") + RISER.format(3.0))
    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", base, "--taxels", "4", "--band", "3000", "6500", "--vary",
                                "neck.diameter", "neck.riser", "--out", out, "--json")
    assert code == 0, err
    data = json.loads(stdout)
    path = out / f"{data['name']}.toml"
    written = spec_mod.load(path)
    board = spec_mod.taxels(written)
    ways = [t.neck.riser for t in board]
    assert ways == [True, True, False, False]
    assert [t["fields"]["neck.riser"] for t in data["taxels"]] == ways
    assert [spec_mod.neck_length_mm(written, t) for t in board] == pytest.approx([9.35, 9.35, 6.35, 6.35])
    for t, asked in zip(board, data["taxels"]):
        f0 = predict(spec_mod.taxel_spec(written, t), mechanics=False).f0_hz
        assert f0 == pytest.approx(asked["target_hz"], rel=0.005), t.name
    assert spec_mod.from_dict(spec_mod.to_dict(written)) == written
    assert all(e.neck_riser is not None for e in written.taxel)  # every entry says its way, as its neck diameter
    code, stdout, err = run_cli("check", path, "--json")
    assert code == 0, stdout + err
    assert not [f for f in json.loads(stdout)["findings"] if f["level"] == "error"]
    code, text, err = run_cli("design", base, "--taxels", "4", "--band", "3000", "6500", "--vary",
                              "neck.diameter", "neck.riser", "--out", tmp_path / "again")
    assert code == 0, err
    assert "neck through the riser, neck 9.35 mm" in text and "cap in a riser pocket, neck 6.35 mm" in text


def test_cli_single_taxel_round_trip(tmp_path, write_spec):
    out = tmp_path / "d"
    code, stdout, err = run_cli("design", _laser_with_riser(write_spec), "--target-hz", str(LOW_HZ), "--vary",
                                *THREE, "neck.riser", "--out", out, "--json")
    assert code == 0, err
    data = json.loads(stdout)
    assert data["fields"]["neck.riser"] == {"start": False, "solved": True}
    path = out / f"{data['name']}.toml"
    assert spec_mod.load(path).neck.riser
    code, stdout, err = run_cli("predict", path, "--json")
    assert code == 0, err
    assert json.loads(stdout)["f0_hz"] == pytest.approx(LOW_HZ, rel=0.005)
    assert run_cli("check", path)[0] == 0


@pytest.mark.parametrize("riser,args,words", [
    (False, ["--target-hz", "5000", "--vary", "neck.diameter", "neck.riser"], "add a [riser] table"),
    (False, ["--taxels", "3", "--band", "3000", "6500", "--vary", "neck.diameter", "neck.riser"],
     "add a [riser] table"),
    (True, ["--target-hz", "5000", "--vary", "neck.riser=1:2"], "without a range"),
    (True, ["--taxels", "3", "--band", "3000", "6500", "--vary", "neck.riser"], "at least one"),
], ids=["no-riser", "no-riser-taxels", "range", "taxels-riser-alone"])
def test_cli_refuses_neck_riser_exit_2(tmp_path, write_spec, riser, args, words):
    spec = write_spec(ARRAY_BASE.format(force="5.0") + (RISER.format(3.0) if riser else ""))
    out = tmp_path / "d"
    code, _, err = run_cli("design", spec, *args, "--out", out)
    assert code == 2 and "--vary neck.riser" in err and words in err and "Traceback" not in err
    assert not out.exists()


def test_a_riser_left_out_of_vary_keeps_each_neck(write_spec):
    """Without --vary neck.riser the spec's own way stays: neck.riser = true solves on the long neck, and a target
    only the plate's neck reaches is refused naming the riser."""
    s = with_fields(spec_mod.load(_laser_with_riser(write_spec)), {"neck.riser": True})
    r = solve(s, 5000.0, parse_vary(s, THREE))
    assert r.spec.neck.riser and _taxel_f0(r.spec) == pytest.approx(5000.0, rel=0.005)
    with pytest.raises(Unreachable, match="6.35 mm [+] the 1.5 mm riser the neck runs through"):
        solve(s, 7000.0, parse_vary(s, THREE))


def test_a_pocket_too_shallow_for_the_press_is_passed_over(write_spec):
    """A cap in a 3 mm riser's pocket keeps 1.89 mm above the clamp, less than the cap mechanics' 2 mm travel: where
    the loaded band needs the cap mechanics (no [calibration]) the long neck is kept although the pocket needs less
    change; with a 1.5 mm travel the pocket is kept. (Without the check `design --taxels` stopped on the pocketed
    taxel's band: "mechanics.displacement_mm must be < 1.894 mm".)"""
    from matcad.design.solve import unpressable

    s = spec_mod.load(_laser_with_riser(write_spec, 3.0))
    pocket = solve(s, 5400.0, parse_vary(s, THREE))
    assert not pocket.spec.neck.riser and "displacement_mm" in unpressable(pocket.spec)
    r = solve(s, 5400.0, parse_vary(s, [*THREE, "neck.riser"]))
    assert r.spec.neck.riser and unpressable(r.spec) is None
    short = with_fields(s, {"mechanics.displacement_mm": 1.5})
    assert not solve(short, 5400.0, parse_vary(short, [*THREE, "neck.riser"])).spec.neck.riser
