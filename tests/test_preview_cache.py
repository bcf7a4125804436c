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
