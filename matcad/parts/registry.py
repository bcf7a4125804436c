"""The part registry: every fabricated part declares one :class:`Part` entry in its own module, and
:func:`parts` discovers them (the way boxes.py discovers its generators). Lengths in mm.

A module of :mod:`matcad.parts` declares its parts in a top-level ``PARTS`` tuple. Discovery imports only the
modules whose source assigns ``PARTS``, so a part module must stay cheap to import: a 3-D part's ``make``
imports the CAD kernel inside the function, never at module level (the laser-only and predict paths never load
build123d; tests enforce it). Adding a part is one module with one ``PARTS`` entry: build, export, previews,
the section's colours and labels, the fabrication steps and the report all iterate :func:`parts`.
"""

from __future__ import annotations

import functools
import importlib
import math
import pkgutil
import re
from dataclasses import dataclass, fields
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from matcad.spec import Spec


class Kind(str, Enum):
    """How a part is made: cut from sheet (DXF/SVG), printed (STL/STEP), or cast in silicone (a reference STL/STEP
    of the cast shape)."""

    LASER = "laser"
    PRINTED = "printed"
    CAST = "cast"


@dataclass(frozen=True)
class PrintPose:
    """How a 3-D part is exported: rotated ``rx_deg`` about x from its design frame, then lifted so its lowest
    point is z = 0 (the bed). ``bed_face`` names the face that lies on the bed, ``printed`` is False for the
    cast silicone cap (a reference shape, not a print)."""

    rx_deg: float
    bed_face: str
    printed: bool = True

    def matrix(self, z_min_rotated: float) -> list[list[float]]:
        """4 x 4 transform from the design frame to the exported (print) frame (mm)."""
        c, s = (round(f(math.radians(self.rx_deg)), 12) + 0.0 for f in (math.cos, math.sin))  # exact for 180°
        return [[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0], [0.0, s, c, -z_min_rotated], [0.0, 0.0, 0.0, 1.0]]


SECTIONS = ("", "axis", "bore")
"""A preview's second view: an orthographic view (''), or a section through y = 0 ('axis') or through an inclined
bore's plane ('bore')."""
DEFAULT_VIEW = ("from above", 90.0, -90.0)
"""(caption, elevation, azimuth in degrees) of a 3-D part's second preview when its entry names no view."""
NON_PART_FLAGS = {
    "assembly": "assembly.step and section.svg: every built part in its assembled place (matcad.parts.assembly)",
    "reference_square": "a drawing option of every laser part (a 10 mm square that proves the scale)",
}
"""``[outputs]`` flags that ask for no part of their own; every other flag must be some part's ``flag``."""
_COLOUR = re.compile(r"#[0-9a-fA-F]{6}")
_DECLARES = re.compile(r"^PARTS\s*[:=]", re.M)


@dataclass(frozen=True)
class Part:
    """One fabricated part: what ``matcad build`` makes when ``[outputs].<flag>`` asks for it and ``when`` holds.

    ``make(spec)`` returns a :class:`matcad.parts.flat.Flat` (laser) or a build123d solid in the part's design
    frame (printed, cast: it imports the kernel itself). ``name`` is the stem of its files and its key in the
    report, previews and section. ``order`` places it in the kit's listings (laser parts, then 3-D ones, as
    ordered). ``colour`` fills it in section.svg (``#rrggbb``, required). 3-D parts need a ``pose`` (how they
    are exported); ``view`` is their preview's second view (caption, elevation, azimuth in degrees;
    :data:`DEFAULT_VIEW` when None). Laser parts name their ``sheet`` (a key of
    :data:`matcad.parts.features.SHEETS`). ``label`` names the part on the section (default: its name spelt
    out). ``section`` draws the preview's second view as a cut instead: 'axis' (through y = 0, every cap's axis)
    or 'bore' (through an inclined bore's plane), so what lies inside shows. ``recipe(spec)`` gives a 3-D part
    made by booleans of simple tools as those tools (:class:`matcad.parts.recipe.Recipe`; ``make`` returns its
    ``solid()``): the design page's preview meshes it from the tools' kept meshes. ``extent(spec)`` is a printed
    part's bounding box in its print pose (x, y, z mm), from the arithmetic its solid is made of (required for
    one, and only for one): the design rule ``print.bed`` holds it to the printer's build volume, without building
    the solid."""

    name: str
    kind: Kind
    flag: str
    make: Callable[[Spec], Any]
    order: int
    colour: str
    pose: PrintPose | None = None
    view: tuple[str, float, float] | None = None
    sheet: str | None = None
    when: Callable[[Spec], bool] | None = None
    label: str = ""
    section: str = ""
    recipe: Callable[[Spec], Any] | None = None
    extent: Callable[[Spec], tuple[float, float, float]] | None = None

    def __post_init__(self):
        from matcad.spec import Outputs

        flags = {f.name for f in fields(Outputs)} - set(NON_PART_FLAGS)
        problems = []
        if not re.fullmatch(r"[a-z][a-z0-9_]*", self.name):
            problems.append(f"name {self.name!r} invalid, must be a lower-case file stem")
        if not isinstance(self.kind, Kind):
            problems.append(f"kind {self.kind!r} invalid, must be one of {[k.value for k in Kind]}")
        if self.flag not in flags:
            problems.append(f"flag {self.flag!r} invalid, must be one of the [outputs] fields {sorted(flags)}")
        if not isinstance(self.colour, str) or not _COLOUR.fullmatch(self.colour):
            problems.append(f"colour {self.colour!r} invalid, must be '#rrggbb' (its fill in section.svg)")
        if (self.kind is Kind.LASER) == (self.pose is not None):
            problems.append("pose must be given for a printed or cast part and only for one")
        if (self.kind is Kind.LASER) != (self.sheet is not None):
            problems.append("sheet must be given for a laser part and only for one")
        if (self.kind is Kind.PRINTED) != (self.extent is not None):
            problems.append("extent must be given for a printed part and only for one")
        if self.section not in SECTIONS:
            problems.append(f"section {self.section!r} invalid, must be one of {SECTIONS}")
        if problems:
            raise ValueError(f"part {self.name!r}: " + "; ".join(problems))

    @property
    def solid(self) -> bool:
        """Whether the part is exported as STL/STEP (needs the CAD kernel)."""
        return self.kind is not Kind.LASER

    @property
    def section_label(self) -> str:
        return self.label or self.name.replace("_", " ")

    def wanted(self, spec: Spec) -> bool:
        """Whether ``spec`` asks for this part: its ``[outputs]`` flag, and its condition if it has one."""
        return bool(getattr(spec.outputs, self.flag)) and (self.when is None or bool(self.when(spec)))


def _declares_parts(path: Path) -> bool:
    try:
        return bool(_DECLARES.search(path.read_text(encoding="utf-8")))
    except OSError:
        return False


@functools.cache
def parts() -> tuple[Part, ...]:
    """Every registered part, in kit order: the ``PARTS`` of each :mod:`matcad.parts` module that declares one."""
    import matcad.parts as package

    found: dict[str, Part] = {}
    for info in pkgutil.iter_modules(package.__path__):
        path = Path(getattr(info.module_finder, "path", "")) / f"{info.name}.py"
        if info.ispkg or not _declares_parts(path):
            continue
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        for part in module.PARTS:
            if not isinstance(part, Part):
                raise TypeError(f"{module.__name__}.PARTS holds {part!r}, not a matcad.parts.registry.Part")
            if part.name in found:
                raise ValueError(f"part {part.name!r} registered twice ({module.__name__})")
            found[part.name] = part
    return tuple(sorted(found.values(), key=lambda p: (p.order, p.name)))


def part(name: str) -> Part:
    """The registered part called ``name``."""
    by_name = {p.name: p for p in parts()}
    if name not in by_name:
        raise ValueError(f"part {name!r} invalid, must be one of {sorted(by_name)}")
    return by_name[name]


def wanted(spec: Spec, kind: Kind | None = None) -> list[Part]:
    """The parts ``spec`` asks for (of ``kind`` only, if given), in kit order."""
    return [p for p in parts() if p.wanted(spec) and (kind is None or p.kind is kind)]
