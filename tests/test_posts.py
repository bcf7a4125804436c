"""Support posts under a long board's neck plate (plate.support_posts): the closed forms they are bent by, their
places clear of every jet, needle and mouth (from the geometry), the built needle mount carrying them to the
plate's underside, and plate.bending silent with them and firing without."""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.design.allocate import stagger
from matcad.materials import ACRYLIC_MODULUS_MPA
from matcad.mechanics.plate import cantilever_deflection_mm, deflection_mm, second_moment_mm4
from tests.conftest import MINIMAL

PITCH_X, HALF_ROW = 10.5, 7.7
"""The 12-taxel 1/16 in capacity board's stagger (`design --taxels 12 --band 1700 11000`, docs/bands.md)."""
TAXELS = [(1.2, 7.632, 8.372), (1.248, 7.177, 8.047), (1.298, 6.756, 7.739), (1.348, 6.365, 7.447),
          (1.4, 6.002, 7.17), (1.453, 5.663, 6.906), (1.507, 5.345, 6.654), (1.563, 5.048, 6.412),
          (1.621, 4.768, 6.181), (1.681, 4.504, 5.958), (1.744, 4.254, 5.743), (1.809, 4.018, 5.535)]
"""Its taxels as designed (neck d, cavity D, cavity L, mm; 1.7-11 kHz): the widest neck clears the posts least."""


def _board(posts: bool):
    taxels = "".join(f"[[taxel]]\nx = {x:g}\ny = {y:g}\nneck_diameter = {d:g}\ncavity_diameter = {cd:g}\n"
                     f"cavity_length = {cl:g}\n" for (x, y), (d, cd, cl) in zip(stagger(12, PITCH_X, HALF_ROW), TAXELS))
    text = (MINIMAL.replace("length = 6.35", "length = 1.5875")
            + f"[plate]\nwidth = 34.5\ndepth = 108.7\nthickness_measured = true\nsupport_posts = {str(posts).lower()}\n"
            + "[end_cap]\nouter_diameter = 7.95\ntop_thickness = 1.908\n[mechanics]\nmax_force_n = 5.0\n"
            + '[calibration]\nv0_mm3 = 32.21\na = -0.0086\nb = 0.4626\narea_convention = "d2/4"\n' + taxels)
    return spec_mod.from_dict(tomllib.loads(text))


@pytest.fixture(scope="module")
def board():
    return _board(True)


def test_cantilever_is_half_a_centrally_loaded_simple_beam():
    """Exact by symmetry: a simply supported beam of span 2l under 2W at mid-span has zero slope there, so each
    half is a cantilever of length l with W at its end (Roark 8.1 case 1a against case 1e)."""
    w, l, b, t = 5.0, 5.25, 12.0, 1.5875
    beam = float(deflection_mm(2 * w, l, l, 2 * l, b, t, ACRYLIC_MODULUS_MPA))
    assert cantilever_deflection_mm(w, l, b, t, ACRYLIC_MODULUS_MPA) == pytest.approx(beam, rel=1e-12)
    assert beam == pytest.approx(w * l ** 3 / (3 * ACRYLIC_MODULUS_MPA * second_moment_mm4(b, t)), rel=1e-12)


def test_posts_stand_between_the_columns_midway_between_rows(board):
    from matcad.parts.features import plate_post_positions_mm
    from matcad.spec import taxels

    posts = plate_post_positions_mm(board)
    ys = sorted(t.y for t in taxels(board))
    assert len(posts) == 11 and all(x == 0.0 for x, _ in posts)
    assert sorted(y for _, y in posts) == pytest.approx([(a + b) / 2 for a, b in zip(ys, ys[1:])])
    assert plate_post_positions_mm(_board(False)) == []


def test_posts_clear_every_jet_needle_and_mouth(board):
    """From the geometry: each post (a column through the gap) against the board.jet rule's own cone, each needle
    as a cylinder from its bore's mouth in the mount's top face to its tip (3-D distance between axes), and each
    neck's mouth edge, >= 3 mount gaps."""
    from matcad.parts.features import needle_axis_mm, needle_tip_mm, plate_post_positions_mm
    from matcad.rules.board import disc_jet_clearance_mm
    from matcad.rules.plate import POST_CLEARANCE_MM, POST_MOUTH_GAPS, support_posts
    from matcad.spec import taxels

    gap, r = board.spacer.height, board.plate.post_diameter / 2
    worst = {"jet": math.inf, "needle": math.inf, "mouth": math.inf}
    for x, y in plate_post_positions_mm(board):
        post = np.array([(x, y, -gap * k / 20) for k in range(21)])
        for t in taxels(board):
            worst["jet"] = min(worst["jet"], *(min(disc_jet_clearance_mm(t, x, y, r, z)) for z in post[:, 2]))
            tip = np.array(needle_tip_mm(t))
            _, u = needle_axis_mm(t)
            back = (tip[2] + gap) / u[2]  # from the tip down the axis to the mount's top face
            needle = tip - np.outer(np.linspace(0, back, 200), u)
            dist = np.linalg.norm(needle[:, None, :] - post[None, :, :], axis=2).min()
            worst["needle"] = min(worst["needle"], dist - t.needle.outer_diameter / 2 - r)
            worst["mouth"] = min(worst["mouth"], math.hypot(x - t.x, y - t.y) - t.neck.diameter / 2 - r)
    assert worst["jet"] > 0
    assert worst["needle"] >= POST_CLEARANCE_MM
    assert worst["mouth"] >= POST_MOUTH_GAPS * gap
    assert support_posts(board) == []


def test_plate_bending_fires_without_posts_and_not_with_them(board):
    from matcad.rules.plate import deflections, plate_bending

    bare = _board(False)
    assert [f.id for f in plate_bending(bare)] == ["plate.bending"]
    assert deflections(bare)[1].max() > bare.spacer.height  # 2.85 mm: the plate reaches the mount
    assert plate_bending(board) == []
    assert deflections(board)[1].max() < 0.05


def test_posts_refused_on_one_column():
    from matcad.rules.plate import support_posts

    s = _board(True)
    one = dataclasses.replace(s, taxel=tuple(dataclasses.replace(t, x=0.0) for t in s.taxel))
    assert [f.id for f in support_posts(one)] == ["plate.posts"]


def test_built_mount_carries_the_posts_to_the_plate_underside(board, tmp_path):
    """The needle mount's STL read back: a circle of the post's diameter at every post, mid-gap, and the mesh's
    top over each post at the plate's underside (z = 0 in the assembly frame)."""
    import trimesh

    from matcad.build import build
    from matcad.parts.features import plate_post_positions_mm
    from tests.readback import nearest_circle, section_circles

    off = {f.name: False for f in dataclasses.fields(board.outputs) if getattr(board.outputs, f.name) is True}
    s = dataclasses.replace(board, outputs=dataclasses.replace(board.outputs, **(off | {"needle_mount": True})))
    build(s, tmp_path / "b", force=True)  # the bare test board's caps are thin-walled (cap.wall): not what is tested
    matrix = np.array(json.loads((tmp_path / "b" / "report.json").read_text())["meshes"]["needle_mount.stl"]
                      ["design_to_print"])
    mesh = trimesh.load_mesh(tmp_path / "b" / "needle_mount.stl")
    mesh.apply_transform(np.linalg.inv(matrix))  # back to the assembly frame
    gap, r = s.spacer.height, s.plate.post_diameter / 2
    assert mesh.bounds[1][2] == pytest.approx(0.0, abs=1e-6)
    circles = section_circles(mesh, -gap / 2)
    for x, y in plate_post_positions_mm(s):
        cx, cy, radius = nearest_circle(circles, x, y)
        assert (cx, cy, radius) == pytest.approx((x, y, r), abs=0.01)
        near = np.hypot(mesh.vertices[:, 0] - x, mesh.vertices[:, 1] - y) <= r + 1e-6
        assert mesh.vertices[near, 2].max() == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("template", ["mat-paper", "mat-array-4", "mat-sla-array", "mat-laser-only"])
def test_templates_carry_no_posts(template):
    """Posts are off unless asked for: every template's mount, labels and bending are those of a plate without
    them (their kits are byte-identical but for the two new fields in report.json's resolved spec)."""
    from matcad.parts.features import plate_post_positions_mm
    from matcad.rules.plate import support_posts
    from tests.conftest import ROOT

    s = spec_mod.load(ROOT / "templates" / f"{template}.toml")
    assert not s.plate.support_posts and plate_post_positions_mm(s) == [] and support_posts(s) == []


def test_rows_spread_until_posts_fit():
    """`design --taxels` on a board whose necks leave no room for posts spreads the stagger's rows
    (:func:`matcad.design.allocate.post_pitch`): the 12-taxel board's necks 0.35 mm wider leave the posts 4.68 mm from
    the widest mouth (< 3 mount gaps, 4.77 mm) at its 7.7 mm half row; the least spread that clears them (8.0 mm),
    read from the relaid board's geometry, has every post at least 3 gaps from every mouth, and one layout step
    less does not."""
    from types import SimpleNamespace

    from matcad.design.allocate import LAYOUT_STEPS_PER_MM, array_spec, board_base, post_pitch, stagger_pitch
    from matcad.design.solve import parse_vary
    from matcad.rules.plate import POST_MOUTH_GAPS, post_clearances_mm, support_posts
    from matcad.spec import taxel_spec, taxels

    s = _board(True)
    single = taxel_spec(s, taxels(s)[0])
    vary = parse_vary(single, ["neck.diameter=0.5:7", "cavity.length", "cavity.diameter=2.1:12"])
    solutions = [SimpleNamespace(spec=single, f0_hz=5000.0, fields={
        "neck.diameter": (None, d + 0.35), "cavity.diameter": (None, cd), "cavity.length": (None, cl)})
        for d, cd, cl in TAXELS]

    def relaid(pitch):
        base, points = board_base(single, 12, vary, pitch)
        spec = array_spec(base, points, solutions, "spread")
        return dataclasses.replace(spec, plate=dataclasses.replace(spec.plate, support_posts=True))

    start = stagger_pitch(single, 7.0)
    assert start == pytest.approx((PITCH_X, HALF_ROW))
    assert "mouth" in " ".join(f.message for f in support_posts(relaid(start))) and "(< 4.77 mm)" in support_posts(
        relaid(start))[0].message
    pitch = post_pitch(single, 12, vary, solutions, "spread")
    assert pitch[0] == PITCH_X and pitch[1] > HALF_ROW
    assert support_posts(relaid(pitch)) == []
    assert min(r["mouth"] for r in post_clearances_mm(relaid(pitch))) >= POST_MOUTH_GAPS * s.spacer.height
    assert support_posts(relaid((pitch[0], pitch[1] - 1 / LAYOUT_STEPS_PER_MM)))
