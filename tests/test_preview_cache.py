"""The design page's preview keeps built parts between edits (issue 23, :class:`matcad.serve.preview.PartCache`):
an edit to one taxel's cavity rebuilds that taxel's cap only, a move rebuilds no cap, and what the cache draws is
byte for byte what the build draws from scratch (section.svg, :func:`matcad.render.section.write_section_svg`)."""

from __future__ import annotations

import copy
import tomllib

import pytest

from matcad.render.section import write_section_svg
from matcad.serve import preview
from matcad.spec import from_dict
from tests.conftest import ROOT

BOARD = ROOT / "templates" / "mat-array-4.toml"
PAPER = ROOT / "templates" / "mat-paper.toml"


def _edited(path, edit) -> tuple[dict, object]:
    data = tomllib.loads(path.read_text())
    edited = copy.deepcopy(data)
    edit(edited)
    return data, from_dict(edited)


def _fresh_svg(spec, tmp_path) -> str:
    path = tmp_path / "section.svg"
    write_section_svg(spec, path)  # what `build` writes: every part built, no cache
    return path.read_text(encoding="utf-8")


def _set(index: int, **values):
    def edit(data):
        data["taxel"][index].update(values)
    return edit


def test_an_edited_board_rebuilds_only_what_the_edit_touches(tmp_path):
    cache = preview.PartCache()
    data, _ = _edited(BOARD, lambda d: None)
    first = preview.section(from_dict(data), cache)
    assert first["svg"] == _fresh_svg(from_dict(data), tmp_path)
    assert cache.built["end_cap_t2"] == 1 and cache.built["neck_plate"] == 1

    cache.built.clear()  # one taxel's cavity (t1: in the section's plane): its cap alone
    _, longer = _edited(BOARD, _set(0, cavity_length=4.0))
    svg = preview.section(longer, cache)["svg"]
    assert dict(cache.built) == {"end_cap_t1": 1}
    assert svg == _fresh_svg(longer, tmp_path) and svg != first["svg"]

    cache.built.clear()  # the physics' tables: nothing
    _, stiffer = _edited(BOARD, lambda d: d["mechanics"].update(max_force_n=2.0))
    preview.section(stiffer, cache)
    assert not cache.built

    cache.built.clear()  # a move: the plate, guides, mount, needles and spacers, no cap
    _, moved = _edited(BOARD, _set(1, x=7.0))
    svg = preview.section(moved, cache)["svg"]
    assert cache.built["neck_plate"] == 1 and not any(n.startswith("end_cap") for n in cache.built)
    assert svg == _fresh_svg(moved, tmp_path)


def test_a_single_taxel_edit_rebuilds_its_cap_and_matches_the_build(tmp_path):
    cache = preview.PartCache()
    data, _ = _edited(PAPER, lambda d: None)
    preview.section(from_dict(data), cache)
    cache.built.clear()
    _, edited = _edited(PAPER, lambda d: d["cavity"].update(length=4.5))
    svg = preview.section(edited, cache)["svg"]
    assert dict(cache.built) == {"end_cap": 1}
    assert svg == _fresh_svg(edited, tmp_path)


@pytest.mark.slow
def test_cached_meshes_are_the_meshes_built_afresh():
    """After a move (no mold rebuilt: the mold ignores positions) the cached meshes equal a fresh cache's."""
    cache = preview.PartCache()
    data, moved = _edited(BOARD, _set(1, x=7.0))
    preview.meshes(from_dict(data), cache)
    cache.built.clear()
    kept = preview.meshes(moved, cache)["parts"]
    assert not any(n.startswith("end_cap") for n in cache.built)
    fresh = preview.meshes(moved, preview.PartCache())["parts"]
    assert [p["name"] for p in kept] == [p["name"] for p in fresh]
    for a, b in zip(kept, fresh):
        assert a["vertices"] == b["vertices"] and a["triangles"] == b["triangles"], a["name"]


def _page_mesh(part: dict):
    """A mesh the page draws, as trimesh reads it (vertices as sent: 3 decimals, mm)."""
    import numpy as np
    import trimesh

    return trimesh.Trimesh(np.reshape(part["vertices"], (-1, 3)), np.reshape(part["triangles"], (-1, 3)),
                           process=False)


@pytest.mark.parametrize("path,edit", [(PAPER, lambda d: d["cavity"].update(length=4.5)),
                                       (BOARD, _set(0, cavity_length=4.5))], ids=["paper", "board"])
def test_the_mold_preview_is_the_mold_the_build_makes(path, edit):
    """The page's mold, mesh booleans of the mold's tools kept between edits (matcad.serve.tessellate), after a cap
    edit with the cache warm, against the solid the build exports triangulated at the preview's tolerance: the same
    volume, surface, number of through holes (genus) and size, and under 0.25 mm³ in one but not the other (a
    vent, ~1.5 mm³, or the labels left out, or a tool kept from before the edit, fail; the lids agree exactly, the
    bases by ~0.08 mm³, the nut funnels' lofts triangulated apart or as faces of the base). On the board the edit
    meshes t1's tools again, not the sockets nor the labels."""
    from manifold3d import Manifold, OpType

    from matcad.parts.registry import part
    from matcad.serve.tessellate import manifold

    cache = preview.PartCache()
    data, edited = _edited(path, edit)
    preview.meshes(from_dict(data), cache, groups=("molds",))
    assert cache.built["_ribbed_socket"] == 2
    cache.built.clear()
    served = {p["name"]: p for p in preview.meshes(edited, cache, groups=("molds",))["parts"]}
    if path == BOARD:
        assert cache.built["_cap_negative"] == cache.built["_core_pin_at"] == 1, cache.built
        assert not cache.built["_ribbed_socket"] and not cache.built["engraved"], cache.built
        for other in (lambda d: d["wall"].update(shear_modulus_mpa=[0.3, 0.6]), _set(1, x=7.0)):  # physics, move
            cache.built.clear()
            assert preview.meshes(_edited(path, lambda d: (edit(d), other(d)))[1], cache, groups=("molds",))
            assert not cache.built, cache.built
    for name in preview.MOLD_PARTS:
        solid = part(name).make(edited)
        built = manifold(solid, preview.MESH_TOLERANCE_MM, preview.ANGULAR_TOLERANCE_RAD)
        drawn, _ = cache.mold(part(name).recipe(edited))
        assert drawn.genus() == built.genus(), name
        assert drawn.volume() == pytest.approx(built.volume(), abs=0.25), name
        assert drawn.surface_area() == pytest.approx(built.surface_area(), rel=1e-5), name
        assert drawn.volume() == pytest.approx(solid.volume, rel=2e-3), name  # and the B-rep's own volume
        apart = sum(Manifold.batch_boolean(pair, OpType.Subtract).volume() for pair in ((drawn, built), (built, drawn)))
        assert apart < 0.25, (name, apart)
        page = _page_mesh(served[name])
        size = solid.bounding_box().size
        assert page.is_watertight and page.volume == pytest.approx(built.volume(), rel=1e-4), name
        assert page.extents == pytest.approx((size.X, size.Y, size.Z), abs=2e-3), name


def test_the_preview_reads_the_triangulation_build123d_reads(tmp_path):
    """matcad.serve.tessellate.triangulate reads the kernel's triangulation in bulk: the same vertices, in the same
    order, and the same triangles (orientation kept) as build123d's Shape.tessellate, on a cap moved and turned (its
    faces carry a location)."""
    import numpy as np
    from build123d import Pos, Rot

    from matcad.parts.end_cap import end_cap
    from matcad.serve.tessellate import triangulate

    cap = Pos(1.0, -2.0, 3.0) * Rot(30, 0, 60) * end_cap(from_dict(tomllib.loads(PAPER.read_text())))
    vertices, triangles = triangulate(cap, preview.MESH_TOLERANCE_MM, preview.ANGULAR_TOLERANCE_RAD)
    theirs, their_triangles = cap.tessellate(preview.MESH_TOLERANCE_MM, preview.ANGULAR_TOLERANCE_RAD)
    assert len(triangles) > 100
    assert np.allclose(vertices, [(v.X, v.Y, v.Z) for v in theirs], rtol=0, atol=1e-12)
    assert np.array_equal(triangles, their_triangles)
