"""`matcad design --target-hz`: inverse design hits its target by `predict`, within rules and stock sheets."""

import dataclasses
import json

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.prediction import predict
from matcad.design import RulesFailed, Unreachable
from matcad.design.solve import FIELDS, get_field, parse_vary, solve
from matcad.output import MANIFEST
from matcad.parts.features import STOCK_ACRYLIC_MM
from matcad.rules import check, errors
from tests.conftest import MINIMAL, PAPER, ROOT, run_cli

LASER = ROOT / "templates" / "mat-laser-only.toml"


@pytest.mark.parametrize("template", [PAPER, LASER], ids=["silicone-wall", "rigid"])
@pytest.mark.parametrize("vary", [["cavity.length"], ["cavity.diameter", "neck.diameter"],
                                  ["neck.length", "neck.diameter"]], ids=lambda v: "+".join(v))
@pytest.mark.parametrize("target", [4200.0, 5000.0, 5200.0])
def test_inverse_design_hits_target_by_predict(template, vary, target):
    s = spec_mod.load(template)
    s = dataclasses.replace(s, calibration=None)  # the physics' own design (a calibrated spec: the next test)
    result = solve(s, target, parse_vary(s, vary))
    f0 = predict(result.spec).f0_hz  # an independent call of the whole prediction on the solved spec
    assert abs(f0 / target - 1) < 0.005 and result.f0_hz == f0
    assert not errors(check(result.spec))
    for field in FIELDS:  # only the varied fields moved
        if field not in vary:
            assert get_field(result.spec, field) == get_field(s, field)
    assert any(abs(get_field(result.spec, f) - get_field(s, f)) > 1e-6 for f in vary)
    if "neck.length" in vary:
        assert result.spec.neck.length in STOCK_ACRYLIC_MM


def test_a_calibrated_spec_is_designed_by_its_calibration():
    """The paper template carries its calibration (f(0) 4010 Hz, physics 5292 Hz): a design for 3800 Hz is 3800 Hz
    by that anchor, its physics-only f0 near 3800 x 5292/4010, and a target the anchored taxel cannot reach says so
    naming the anchor."""
    s = spec_mod.load(PAPER)
    result = solve(s, 3800.0, parse_vary(s, ["cavity.length"]))
    p = predict(result.spec, mechanics=False)
    assert p.model == "calibration" and p.f0_hz == pytest.approx(3800.0, rel=0.005)
    assert result.spec.cavity.length > s.cavity.length
    assert p.physics_f0_hz / p.f0_hz == pytest.approx(5292.3 / 4010.4, rel=0.03)
    with pytest.raises(Unreachable, match=r"\(calibration\) reaches"):
        solve(s, 5900.0, parse_vary(s, ["cavity.diameter", "neck.diameter"]))


def test_neck_diameter_alone_and_a_range():
    s = spec_mod.load(LASER)
    for target in (4000.0, 4500.0, 6000.0):
        r = solve(s, target, parse_vary(s, ["neck.diameter=1.2:3.0"]))
        assert abs(predict(r.spec).f0_hz / target - 1) < 0.005 and 1.2 <= r.spec.neck.diameter <= 3.0


def test_sheet_alone_picks_the_nearest_stock_sheet():
    s = spec_mod.load(LASER)
    r = solve(s, 4300.0, parse_vary(s, ["neck.length"]))
    stock_f0 = {t: predict(spec_mod.variant(s, "neck", length=t)).f0_hz for t in STOCK_ACRYLIC_MM}
    best = min(stock_f0, key=lambda t: abs(stock_f0[t] / 4300.0 - 1))
    assert r.spec.neck.length == best and r.notes and "stock" in r.notes[0]


def test_unreachable_and_rule_failures():
    s = spec_mod.load(LASER)
    with pytest.raises(Unreachable, match=r"neck.diameter 1-3.18 mm.* reaches \d+-\d+ Hz") as err:
        solve(s, 30000.0, parse_vary(s, ["neck.diameter"]))
    ends = [predict(spec_mod.variant(s, "neck", diameter=d)).f0_hz for d in (1.0, 3.18)]  # f0 rises with d
    assert f"reaches {ends[0]:.0f}-{ends[1]:.0f} Hz" in str(err.value)
    paper = spec_mod.load(PAPER)  # 3 kHz by its calibration needs a ~1.1 mm neck: below the laser's 1 mm feature
    with pytest.raises(RulesFailed) as err:   # after kerf
        solve(paper, 3000.0, parse_vary(paper, ["neck.diameter"]))
    assert any(f.id == "laser.feature" for f in err.value.findings)


def test_the_default_cavity_range_leaves_a_silicone_wall_that_demolds():
    """Deliberate fault caught: the default cavity.diameter range ran to the cap's outside, so a low target was
    met by a cap whose wall `check` says tears on demolding (issue 24: 0.09 mm walls on the 12-taxel board; here
    2600 Hz gave a 0.57 mm wall). It stops at the thinnest wall that demolds; the message names the range."""
    from matcad.rules.printing import MIN_SILICONE_WALL_MM

    s = spec_mod.load(LASER)
    top = s.end_cap.outer_diameter - 2 * MIN_SILICONE_WALL_MM
    r = solve(s, 3000.0, parse_vary(s, ["cavity.diameter"]))
    assert r.spec.cavity.diameter <= top + 1e-9 and not [f for f in check(r.spec) if f.id == "cap.wall"]
    with pytest.raises(Unreachable, match=f"cavity.diameter 2.1-{top:g} mm"):
        solve(s, 2600.0, parse_vary(s, ["cavity.diameter"]))


@pytest.mark.parametrize("items,words", [
    (["neck.width"], "must be one of neck.diameter"), (["neck.diameter=3:1"], "0 < LO < HI"),
    (["neck.length=1:2"], "stock"), (["neck.diameter", "neck.diameter"], "twice")])
def test_bad_vary_names_the_field(items, words):
    with pytest.raises(ValueError, match=words):
        parse_vary(spec_mod.load(LASER), items)


def test_cli_writes_a_spec_predict_agrees_with(tmp_path):
    out = tmp_path / "d"
    code, stdout, err = run_cli("design", LASER, "--target-hz", "5500", "--vary", "cavity.length", "--out", out,
                                "--json")
    assert code == 0, err
    data = json.loads(stdout)
    # the picture is new: the target, f0 along the varied field and the solved section (plot_design.png)
    assert sorted(p.name for p in out.iterdir()) == sorted([MANIFEST, "design.json", data["name"] + ".toml",
                                                            "plot_design.png"])
    assert data["written"][-1] == "plot_design.png"
    code, stdout, err = run_cli("predict", out / f"{data['name']}.toml", "--json")
    assert code == 0, err
    assert abs(json.loads(stdout)["f0_hz"] / 5500 - 1) < 0.005
    assert code == 0 and run_cli("check", out / f"{data['name']}.toml")[0] == 0
    assert data["seconds"] > 0 and abs(data["error"]) < 0.005


@pytest.mark.parametrize("args,code,words", [
    (["--target-hz", "30000", "--vary", "neck.diameter"], 2, "unreachable"),
    (["--target-hz", "-5", "--vary", "neck.diameter"], 2, "--target-hz"),
    (["--target-hz", "5000", "--vary", "plate.width"], 2, "--vary plate.width"),
    (["--target-hz", "5000"], 2, "--vary"),
    (["--taxels", "3"], 2, "--band"),
])
def test_cli_bad_input_exit_2_nothing_written(tmp_path, args, code, words):
    out = tmp_path / "d"
    rc, _, err = run_cli("design", LASER, *args, "--out", out)
    assert rc == code and words in err and "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_cli_rule_failure_exit_1(tmp_path):
    rc, stdout, err = run_cli("design", PAPER, "--target-hz", "3000", "--vary", "neck.diameter", "--out",
                              tmp_path / "d")
    assert rc == 1 and "laser.feature" in stdout and "nothing written" in err and not (tmp_path / "d").exists()


ARRAY_BASE = MINIMAL.replace('name = "t"', 'name = "arr"') + """[plate]
thickness_measured = true
[outputs]
end_cap_mold = false
needle_mount = false
assembly = false
[mechanics]
max_force_n = {force}
[calibration]
v0_mm3 = 32.21
a = -0.0086
b = 0.4626
area_convention = "d2/4"
"""
"""A rigid-wall taxel on a calipered sheet, its load rise from the paper's Eq. 5 (no FElupe in these tests)."""


def _array_base(write_spec, max_force="5.0"):
    return write_spec(ARRAY_BASE.format(force=max_force))


def test_taxels_bands_are_disjoint_inside_the_band_and_check_accepts(tmp_path, write_spec):
    from matcad.listening import guard_hz
    from matcad.prediction.bands import conflicts, taxel_bands
    from matcad.spec import taxels

    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", _array_base(write_spec), "--taxels", "3", "--band", "3500", "6500",
                                "--out", out, "--json")
    assert code == 0, err
    data = json.loads(stdout)
    written = spec_mod.load(out / f"{data['name']}.toml")
    board = taxels(written)
    assert len(board) == 3 and len({(t.x, t.y) for t in board}) == 3
    assert len({t.neck.diameter for t in board}) == 3  # each taxel solved for its own band
    bands = taxel_bands(written)  # recomputed from the written file, not the designer's numbers
    assert {b.model for b in bands} == {"calibration"}  # allocated by the anchored bands
    assert conflicts(bands, guard_hz(written.microphone.sample_rate_hz)) == []
    assert all(3500 <= b.loaded_hz[0] < b.loaded_hz[1] <= 6500 for b in bands)
    assert "plot_taxel_bands.png" in data["written"] and (out / "plot_taxel_bands.png").stat().st_size > 5000
    assert [round(b.loaded_hz[1]) for b in bands] == [round(t["loaded_hz"][1]) for t in data["taxels"]]
    code, stdout, err = run_cli("check", out / f"{data['name']}.toml", "--json")
    assert code == 0, stdout + err
    code, stdout, err = run_cli("predict", out / f"{data['name']}.toml", "--json")
    assert code == 0, err
    assert [t["name"] for t in json.loads(stdout)["taxels"]] == ["t1", "t2", "t3"]


@pytest.mark.parametrize("vary, widest", [({"neck.diameter": None}, 3.18), ({"neck.diameter": (0.5, 7.0)}, 7.0)],
                         ids=["default", "to-7mm"])
def test_taxel_layout_is_jet_free_by_construction(vary, widest):
    """Issue 24: the old square grid put a row's necks in the upstream needles' jets (18 board.jet findings on the
    12-taxel board). The stagger board_base lays out for 2-24 taxels of templates/mat-array-4.toml's needle and
    neck, every neck the widest the --vary range allows (the worst case; the cavity as wide where it must be), gets
    no board.jet finding and no error from the board rules themselves; its pitch is the least that does: half a
    row flatter by one step, a neck is in a jet (when the jet, not the flange spacing, sets the pitch)."""
    from types import SimpleNamespace

    from matcad.design.allocate import (LAYOUT_STEPS_PER_MM, array_spec, board_base, stagger, stagger_pitch,
                                        widest_neck_mm)
    from matcad.rules import board

    template = spec_mod.load(ROOT / "templates" / "mat-array-4.toml")
    base = spec_mod.taxel_spec(template, spec_mod.taxels(template)[0])
    assert widest_neck_mm(base, vary) == widest
    solved = SimpleNamespace(spec=base, f0_hz=5000.0, fields={
        "neck.diameter": (base.neck.diameter, widest),
        "cavity.diameter": (base.cavity.diameter, max(widest, base.cavity.diameter))})
    for n in range(2, 25):
        plate, points = board_base(base, n, vary)
        spec = array_spec(plate, points, [solved] * n, f"s{n}")
        found = [f for rule in (board.plate_fit, board.spacing, board.jet_interference, board.plate_ligaments,
                                board.bore_crossings) for f in rule(spec) if f.id == "board.jet" or f.level == "error"]
        assert found == [], (n, [f.message for f in found])
        assert len({x for x, _ in points}) == 2 and len({y for _, y in points}) == n
    pitch_x, half_row = stagger_pitch(base, widest)
    pitch = spec_mod.cap_flange_diameter_mm(base) + base.machine.laser_min_feature
    flatter = half_row - 1 / LAYOUT_STEPS_PER_MM
    if flatter >= pitch / 2:
        assert board.jet_interference(array_spec(plate, stagger(3, pitch_x, flatter), [solved] * 3, "flatter"))
    else:  # the flange spacing sets the pitch: a hexagonal packing, every neighbour a pitch apart
        assert vary["neck.diameter"] is None and (pitch_x, half_row) == (11.3, pitch / 2)


def test_designed_board_has_no_jet_finding(tmp_path, write_spec):
    """`design --taxels 4` writes two staggered columns that `check` passes with no board.jet finding (the old 2 x 2
    grid put t2's neck in t1's jet and t4's in t3's)."""
    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", _array_base(write_spec), "--taxels", "4", "--band", "3500", "7000",
                                "--out", out, "--json")
    assert code == 0, err
    path = out / f"{json.loads(stdout)['name']}.toml"
    board = spec_mod.taxels(spec_mod.load(path))
    assert [t.x < 0 for t in board] == [True, False, True, False]
    assert [a.y > b.y for a, b in zip(board, board[1:])] == [True] * 3
    code, stdout, err = run_cli("check", path, "--json")
    assert code == 0, stdout + err
    ids = [f["id"] for f in json.loads(stdout)["findings"]]
    assert "bands.allocation" in ids and "board.jet" not in ids


def test_designed_board_says_what_check_warns_of(tmp_path, write_spec):
    """`design --taxels` prints the written board's design-rule warnings and lists every finding in its JSON, the
    same as `check` on the written file. Four taxels on a 1/16 in sheet bend it 0.16 mm under a 5 N press and move
    a pitch 16 Hz (`plate.bending`): the board is written with support posts under the plate, which leave 0.031 mm,
    still -15 Hz on its highest taxel (the cantilever from the post line, docs/arrays.md): the warning stays."""
    base = write_spec(ARRAY_BASE.format(force="5.0").replace("length = 6.35", "length = 1.5875"))
    out = tmp_path / "arr"
    args = ("design", base, "--taxels", "4", "--band", "1700", "11000")
    code, stdout, err = run_cli(*args, "--out", out, "--json")
    assert code == 0, err
    data = json.loads(stdout)
    code, checked, err = run_cli("check", out / f"{data['name']}.toml", "--json")
    assert code == 0, checked + err
    assert data["findings"] == json.loads(checked)["findings"]
    assert spec_mod.load(out / f"{data['name']}.toml").plate.support_posts
    (bending,) = [f for f in data["findings"] if f["id"].startswith("plate.")]
    assert bending["id"] == "plate.bending" and "0.0311 mm" in bending["message"] and "post line" in bending["message"]
    code, text, err = run_cli(*args, "--out", tmp_path / "again")
    assert code == 0, err
    warned = [line.split()[1] for line in text.splitlines() if line.startswith("  warning ")]
    assert "plate.bending" in warned
    assert warned == [f["id"] for f in data["findings"] if f["level"] == "warning"]


def test_taxels_that_do_not_fit_exit_2(tmp_path, write_spec):
    code, _, err = run_cli("design", _array_base(write_spec, "20.0"), "--taxels", "4", "--band", "4000", "5000",
                           "--out", tmp_path / "d")
    assert code == 2 and "4 disjoint bands do not fit" in err and "Bands so far" in err
    assert not (tmp_path / "d").exists()
    code, _, err = run_cli("design", _array_base(write_spec), "--taxels", "2", "--band", "4000", "6000", "--vary",
                           "neck.length", "--out", tmp_path / "d")
    assert code == 2 and "shared by every taxel" in err


def test_taxels_interleave_with_harmonics_and_check_warns(tmp_path, write_spec):
    """Issue 24: a band that another taxel's 2f lands in is no longer moved above the harmonic (t1's 2f, 5.0-5.5 kHz
    by its calibration, covers the 7th and 8th bands' place). The bands sit side by side, the guard apart;
    `check` passes with a bands.harmonic warning (the board tracker discounts the harmonic)."""
    from matcad.listening import guard_hz
    from matcad.prediction.bands import conflicts, taxel_bands

    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", _array_base(write_spec), "--taxels", "8", "--band", "2500", "6000",
                                "--vary", "neck.diameter", "cavity.length", "--out", out, "--json")
    assert code == 0, err
    written = spec_mod.load(out / f"{json.loads(stdout)['name']}.toml")
    bands = taxel_bands(written)
    guard = guard_hz(written.microphone.sample_rate_hz)
    gaps = [b.loaded_hz[0] - a.loaded_hz[1] for a, b in zip(bands, bands[1:])]
    assert all(guard <= g < guard + 10.0 for g in gaps), gaps
    assert [c.harmonic for c in conflicts(bands, guard)] and all(c.harmonic > 1 for c in conflicts(bands, guard))
    code, stdout, err = run_cli("check", out / f"{json.loads(stdout)['name']}.toml")
    assert code == 0 and "bands.harmonic" in stdout and "warning" in stdout, stdout + err


def _capacity_board(write_spec, out, taxels: int, band: tuple[str, str], sheet: str, rate: str = "",
                    needle_mount: bool = False):
    """`design --taxels` of the capacity boards (issue 24; benchmarks/design.py --capacity-only): 5 N per taxel on a
    ``sheet`` mm calipered sheet, neck and cavity free, at ``rate`` Hz when given; (design --json, written spec
    path), `check` of it passed."""
    text = ARRAY_BASE.format(force="5.0").replace("length = 6.35", f"length = {sheet}")
    if needle_mount:
        text = text.replace("needle_mount = false", "needle_mount = true")
    text += f"[microphone]\nsample_rate_hz = {rate}\n" if rate else ""
    code, stdout, err = run_cli("design", write_spec(text), "--taxels", str(taxels), "--band", *band, "--vary",
                                "neck.diameter=0.5:7", "cavity.length", "cavity.diameter=2.1:12", "--out", out,
                                "--json")
    assert code == 0, err
    data = json.loads(stdout)
    path = out / f"{data['name']}.toml"
    code, stdout, err = run_cli("check", path)
    assert code == 0, stdout + err
    return data, path


def _tracked_within_1_hz(written, seed: int = 0) -> None:
    """Every taxel of ``written`` tracked within 1 Hz (mean over its voiced frames) on a synthetic board recording
    (matcad.loop.synth_board.spec_recording: presses on every third, harmonics at -20/-30 dB), heard in its
    listening bands."""
    from matcad.loop import synth_board
    from matcad.loop.board import analyze_board
    from matcad.prediction.bands import listening_bands

    listen = listening_bands(written)
    rec = synth_board.spec_recording(written, seed)
    for k, t in enumerate(analyze_board([rec.x], rec.fs, listen)):
        a = t.analysis
        assert a is not None, t.reason
        assert abs(np.mean(a.track_hz[a.voiced] - rec.truth_at(k, a.times_s[a.voiced]))) < 1.0, t.name


@pytest.mark.slow
def test_twelve_taxels_on_one_microphone(tmp_path, write_spec):
    """Issue 24's capacity target at 44.1 kHz: 12 taxels with 5 N each (a 1/16 in sheet, neck and cavity free),
    `check` without errors, and every taxel tracked within 1 Hz (mean over voiced frames) on a synthetic board
    recording with presses on every third and harmonics at -20/-30 dB (benchmarks/design.py --capacity-only)."""
    _, path = _capacity_board(write_spec, tmp_path / "arr", 12, ("1700", "11000"), "1.5875")
    written = spec_mod.load(path)
    assert len(spec_mod.taxels(written)) == 12
    _tracked_within_1_hz(written)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_sixteen_taxels_at_96_khz(tmp_path, write_spec, seed):
    """Issue 24's capacity target at 96 kHz: 16 taxels with 5 N each (a 0.8 mm sheet, neck and cavity free), `check`
    without errors, and every taxel tracked within 1 Hz on a synthetic board recording at 96 kHz (presses on every
    third, harmonics at -20/-30 dB). Deliberate fault caught: without the predicted harmonics discounted before
    tracking (matcad.loop.overtones) and the room's tails before press steps left out, the cavity-length board's
    t8 read t1's moving 2f (75.7 Hz off, seed 1; benchmarks/design.py --capacity-only runs 5 seeds and both routes)."""
    _, path = _capacity_board(write_spec, tmp_path / "arr", 16, ("1200", "30000"), "0.8", "96000.0")
    written = spec_mod.load(path)
    assert len(spec_mod.taxels(written)) == 16
    _tracked_within_1_hz(written, seed)


@pytest.mark.slow
def test_sixteen_taxels_at_96_khz_on_a_flat_board(tmp_path, write_spec):
    """The 96 kHz capacity board that stays flat: 16 taxels with 5 N each on a 1/8 in (3.175 mm) sheet. At the jet-free
    stagger its posts come 4.61-4.76 mm from the widest mouths (< 3 mount gaps), so `design` spreads the rows until
    they fit (:func:`matcad.design.allocate.post_pitch`) and solves again; the written board carries the posts,
    `check` passes with no plate.bending finding (every taxel's pitch moves at most 2.0 Hz under a 5 N press; limit
    11.7 Hz), `build` writes the kit with the posted needle mount, and every taxel is tracked within 1 Hz on a
    synthetic board recording at 96 kHz (harmonics at -20/-30 dB, presses on every third)."""
    from matcad.listening import guard_hz
    from matcad.parts.features import plate_post_positions_mm
    from matcad.rules.plate import BENDING_GUARD_SHARE, bendings

    data, path = _capacity_board(write_spec, tmp_path / "arr", 16, ("1200", "30000"), "3.175", "96000.0",
                                 needle_mount=True)
    assert "plate.bending" not in {f["id"] for f in data["findings"]}
    written = spec_mod.load(path)
    assert written.plate.support_posts and len(plate_post_positions_mm(written)) == 15
    jets = [f for f in check(written) if f.id == "jet.strouhal"]  # each needle's flow matched to its pitch, to
    assert len(jets) == 16 and all(f.level == "info" and abs(f.value - 1) < 0.02 for f in jets)  # 0.01 L/min
    assert max(abs(b.shift_hz) for b in bendings(written)) <= BENDING_GUARD_SHARE * guard_hz(96000.0)
    assert not {"plate.bending", "plate.posts"} & {f.id for f in check(written)}
    code, stdout, err = run_cli("build", path, "--out", tmp_path / "kit")
    assert code == 0, stdout + err
    assert {"needle_mount.stl", "neck_plate.dxf", "spacer.dxf"} <= {p.name for p in (tmp_path / "kit").iterdir()}
    _tracked_within_1_hz(written)


def test_taxels_choose_the_plate_sheet_among_stock_sheets(tmp_path, write_spec):
    """`design --taxels 3 --vary neck.length neck.diameter`: a 6.35 mm sheet tops out at 4.9 kHz, below 5-6.5 kHz (1 N
    each), so the plate goes to the stock sheet nearest it (in ratio) on which the three bands fit and the plate
    stays flat; every nearer sheet is named as passed over, and the written board's bands lie in the band
    (recomputed from the file)."""
    from matcad.design.solve import stock_order
    from matcad.prediction.bands import taxel_bands

    base = write_spec(ARRAY_BASE.format(force="1.0"))
    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", base, "--taxels", "3", "--band", "5000", "6500", "--vary", "neck.length",
                                "neck.diameter", "--out", out, "--json")
    assert code == 0, err
    data = json.loads(stdout)
    written = spec_mod.load(out / f"{data['name']}.toml")
    sheet = written.neck.length
    assert sheet in STOCK_ACRYLIC_MM and sheet < 6.35
    order = stock_order(spec_mod.load(base))
    nearer = order[:order.index(sheet)]
    note = data["notes"][0]
    assert note.startswith(f"neck.length = {sheet:g} mm") and all(f"{t:g} mm (" in note for t in nearer)
    assert all(5000 <= b.loaded_hz[0] < b.loaded_hz[1] <= 6500 for b in taxel_bands(written))
    assert "plate.bending" not in {f["id"] for f in data["findings"]}
    code, _, err = run_cli("design", base, "--taxels", "3", "--band", "5000", "6500", "--vary", "neck.length")
    assert code == 2 and "at least one" in err
