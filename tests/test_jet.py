"""The needle jet against the taxel's pitch (jet.strouhal): the paper's operating point as the closed-form anchor,
St's scaling, the rule on the templates, the Mach limit, and the sweep's array counts equal to the rule's."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.acoustics import edgetone
from matcad.rules.jet import array_counts, jet_strouhal
from tests.conftest import ROOT


def test_the_papers_point_is_one_and_st_scales_as_f_d_bore2_over_flow():
    """St = f d / U with U = Q / (π D²/4): at the paper's 4.0 kHz, 2.10 mm, 1.5 L/min, 1.52 mm the jet is 13.78 m/s
    and St 0.610; doubling f or d doubles St, doubling the flow halves it, and the needle's diameter enters squared —
    so a needle with the paper's bore-to-outside ratio has the same ratio whichever diameter is read as the bore."""
    u = 1.5 / 60e3 / (math.pi / 4 * 1.52e-3 ** 2)
    assert edgetone.needle_jet_speed_m_s(1.5, 1.52) == pytest.approx(u, rel=1e-12) == pytest.approx(13.78, abs=0.01)
    assert edgetone.mat_strouhal(**edgetone.PAPER_JET) == pytest.approx(4000 * 2.1e-3 / u, rel=1e-12)
    assert edgetone.mat_strouhal_ratio(4000.0, 2.10, 1.5, 1.52) == pytest.approx(1.0, rel=1e-12)
    assert edgetone.mat_strouhal_ratio(8000.0, 2.10, 1.5, 1.52) == pytest.approx(2.0, rel=1e-12)
    assert edgetone.mat_strouhal_ratio(4000.0, 4.20, 1.5, 1.52) == pytest.approx(2.0, rel=1e-12)
    assert edgetone.mat_strouhal_ratio(4000.0, 2.10, 3.0, 1.52) == pytest.approx(0.5, rel=1e-12)
    assert edgetone.mat_strouhal_ratio(4000.0, 2.10, 1.5, 1.52 * 0.8) == pytest.approx(0.64, rel=1e-12)
    assert edgetone.MAT_ST_SPAN == (0.5, 1.5)


def test_templates_jets_and_the_flow_that_matches():
    """The paper's template sits at its own point (St 1.00 x, info); mat-array-4's 6.4-8.8 kHz taxels at the
    paper's 1.5 L/min would be 1.99-2.51 x (warned: too slow to drive them), so the template gives each its own flow,
    and the flow each warning names brings its taxel back to 1.00 x."""
    from matcad.rules import check

    paper = [f for f in check(spec_mod.load(ROOT / "templates" / "mat-paper.toml")) if f.id == "jet.strouhal"]
    assert [(f.level, round(f.value, 2)) for f in paper] == [("info", 1.0)]
    board = spec_mod.load(ROOT / "templates" / "mat-array-4.toml")
    assert all(f.level == "info" for f in check(board) if f.id == "jet.strouhal")
    shared = dataclasses.replace(board, taxel=tuple(dataclasses.replace(t, needle_flow_l_min=None)
                                                    for t in board.taxel))
    warned = [f for f in check(shared) if f.id == "jet.strouhal" and f.level == "warning"]
    assert [f.message.split(":")[0] for f in warned] == ["t2", "t3", "t4"]
    assert [round(f.value, 2) for f in warned] == [1.99, 2.41, 2.51] and all("too slow" in f.message for f in warned)
    for f in warned:
        k = int(f.message[1]) - 1
        flow = float(f.fix.split("near ")[1].split(" L/min")[0])
        fixed = dataclasses.replace(shared, taxel=tuple(dataclasses.replace(t, needle_flow_l_min=flow) if i == k
                                                        else t for i, t in enumerate(shared.taxel)))
        again = [g for g in check(fixed) if g.id == "jet.strouhal" and g.message.startswith(f"t{k + 1}:")]
        assert [g.level for g in again] == ["info"] and again[0].value == pytest.approx(1.0, abs=0.01)


def test_a_jet_past_mach_0_3_is_warned():
    """At 40 kHz across the paper's 2.10 mm neck the jet that matches the paper's point is 13.78 x 10 = 138 m/s,
    above 0.3 c (103.8 m/s at 25 °C): warned whatever the flow; at 20 kHz (69 m/s) it is not."""
    s = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
    at = [SimpleNamespace(f0_hz=f, speed_of_sound_m_s=346.1) for f in (40000.0, 20000.0)]
    hot = jet_strouhal(s, at[0])
    assert any(f.level == "warning" and "Mach 0.3" in f.message for f in hot)
    assert not any("Mach" in f.message for f in jet_strouhal(s, at[1]))


def test_array_counts_equal_the_rule_per_variant():
    """A sweep's verdict columns count the rule's warnings on arrays (matcad.sweep.arrays.rule_columns): equal to
    the rule's own findings variant by variant, across the window's edges and the Mach limit."""
    s = spec_mod.load(ROOT / "templates" / "mat-paper.toml")
    f0 = np.array([1000.0, 1900.0, 2100.0, 4000.0, 5900.0, 6100.0, 12000.0, 40000.0, 80000.0])
    d = np.array([2.1, 2.1, 2.1, 2.1, 2.1, 2.1, 1.0, 2.1, 0.5])
    c = 346.0
    counts = array_counts(f0, d, np.full(len(f0), 1.5), np.full(len(f0), 1.52), np.full(len(f0), c))
    for k in range(len(f0)):
        spec_k = dataclasses.replace(s, neck=dataclasses.replace(s.neck, diameter=float(d[k])))
        p = SimpleNamespace(f0_hz=float(f0[k]), speed_of_sound_m_s=c)
        rule = [f for f in jet_strouhal(spec_k, p) if f.level == "warning"]
        assert counts[("jet.strouhal", "warning")][k] == len(rule), k
    assert counts[("jet.strouhal", "warning")].tolist() == [1, 1, 0, 0, 0, 1, 0, 2, 1]


def test_designed_board_matches_each_needles_flow_to_its_pitch(tmp_path, write_spec):
    """`design --taxels 3` writes each taxel's needle_flow_l_min so that its jet sits at the paper's point: the
    written board's jet.strouhal findings are all info at 1.00 x (to the flow's 0.01 L/min), where the shared
    1.5 L/min would give each taxel St in proportion to its f0 d."""
    import json

    from matcad.rules import check
    from matcad.spec import taxels
    from tests.conftest import run_cli
    from tests.test_design import ARRAY_BASE

    out = tmp_path / "arr"
    code, stdout, err = run_cli("design", write_spec(ARRAY_BASE.format(force="5.0")), "--taxels", "3", "--band",
                                "3500", "6500", "--out", out, "--json")
    assert code == 0, err
    written = spec_mod.load(out / f"{json.loads(stdout)['name']}.toml")
    flows = [t.needle.flow_l_min for t in taxels(written)]
    assert len(set(flows)) == 3 and flows == sorted(flows)  # a higher pitch needs a faster jet
    jets = [f for f in check(written) if f.id == "jet.strouhal"]
    assert len(jets) == 3 and all(f.level == "info" and f.value == pytest.approx(1.0, abs=0.01) for f in jets)
