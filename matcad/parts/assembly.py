"""Every part in its assembled place (assembly frame: plate underside z = 0, neck axis = z), for assembly.step and
the section (:func:`matcad.render.section.write_section_svg`).

Stack, bottom to top: needle mount, spacers (gap = spacer.height), neck plate (0..l), the riser bonded on it
when the spec has one (l..l + r), locator guide around the caps' flanges, each cap on its seat (the riser where
its neck runs on through it, else the plate, in a pocket of the riser), the clamp guide resting on the flanges
(unclamped: the flange's squeeze shows as a gap that the bolts close; heights from :mod:`matcad.parts.stack`).
build123d is imported inside the functions, as in every part module.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from matcad.parts.end_cap import end_cap
from matcad.parts.features import plate_bolt_positions_mm
from matcad.parts.guide import guide
from matcad.parts.neck_plate import neck_plate
from matcad.parts.needle_mount import needle, needle_mount, taxel_needle
from matcad.parts.solid import flat_solid
from matcad.parts.spacer import spacer
from matcad.parts.riser import riser
from matcad.parts.stack import cap_seat_z_mm, clamp_seat_z_mm, locator_z_mm

if TYPE_CHECKING:
    from build123d import Compound


def drilled(plate, neck_diameters: tuple[float, ...]):
    """The neck plate (or the riser) as assembled: the pilot-cut necks (in board order) drilled to their finished
    diameters (mm)."""
    import dataclasses

    finished = iter(neck_diameters)
    holes = tuple(dataclasses.replace(h, diameter=next(finished), purpose="neck") if h.purpose == "neck_pilot"
                  else h for h in plate.holes)
    return dataclasses.replace(plate, holes=holes)


def _build(name: str, cap, build):
    """The default ``memo`` of :func:`assembled_parts`: build every part."""
    return build()


def assembled_parts(spec, made: dict | None = None, memo=_build) -> dict[str, object]:
    """Name → solid in the assembly frame (mm). Spacers are numbered when laser-cut; a board's caps and needles
    are named after their taxels (end_cap_t1, needle_t1, ...). ``made``: solids the build already made in their
    design frame (:func:`matcad.parts.catalogue.printed_parts`): a single taxel's cap and the needle mount are
    placed from those (moved copies) instead of being built again. ``memo(name, cap, build)`` returns the solid
    ``build()`` makes, or an equal one it kept (the design page's preview caches parts,
    :mod:`matcad.serve.preview`): ``cap`` is the single-taxel spec a cap is made from (its position dropped),
    None for a part that depends on the whole board."""
    from build123d import Pos

    from matcad.spec import taxel_spec, taxels

    made = made or {}
    board = taxels(spec)

    def reuse(name, build, cap=None):
        return Pos(0, 0, 0) * made[name] if name in made else memo(name, cap, build)

    parts = {
        "neck_plate": memo("neck_plate", None, lambda: flat_solid(drilled(neck_plate(spec),
                                                                          tuple(t.neck.diameter for t in board)))),
    }
    if spec.riser is not None:
        through = tuple(t.neck.diameter for t in board if t.neck.riser)
        parts["riser"] = memo("riser", None, lambda: flat_solid(drilled(riser(spec), through), spec.neck.length))
    parts |= {
        "guide_locator": memo("guide_locator", None, lambda: flat_solid(guide(spec, "locator"), locator_z_mm(spec))),
        "guide_clamp": memo("guide_clamp", None, lambda: flat_solid(guide(spec, "clamp"), clamp_seat_z_mm(spec))),
    }
    if len(board) == 1:
        parts |= {"end_cap": Pos(0, 0, cap_seat_z_mm(spec)) * reuse("end_cap", lambda: end_cap(spec), cap=spec),
                  "needle_mount": reuse("needle_mount", lambda: needle_mount(spec)),
                  "needle": memo("needle", None, lambda: needle(spec))}
    else:
        caps = {t.name: taxel_spec(spec, t) for t in board}
        parts |= {f"end_cap_{t.name}": Pos(t.x, t.y, cap_seat_z_mm(spec, t))
                  * memo(f"end_cap_{t.name}", caps[t.name], lambda c=caps[t.name]: end_cap(c)) for t in board}
        parts["needle_mount"] = reuse("needle_mount", lambda: needle_mount(spec))
        parts |= {f"needle_{t.name}": memo(f"needle_{t.name}", None, lambda t=t: taxel_needle(t)) for t in board}
    if spec.spacer.style == "laser":
        one = spacer(spec)
        for i, (x, y) in enumerate(plate_bolt_positions_mm(spec), 1):
            # each spacer its own solid: moved copies of one solid share one STEP product, named after the last
            parts[f"spacer_{i}"] = memo(f"spacer_{i}", None,
                                        lambda x=x, y=y: Pos(x, y, 0) * flat_solid(one, -spec.spacer.height))
    return parts


def assembly(spec, parts=None) -> Compound:
    """All parts (``assembled_parts`` unless given) as one labelled compound (for assembly.step)."""
    from build123d import Compound

    children = []
    for name, solid in (parts or assembled_parts(spec)).items():
        solid.label = name
        children.append(solid)
    return Compound(label=spec.name, children=children)
