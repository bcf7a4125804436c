"""A printed part as the calls that make it: a stock solid, the tools fused to it, the tools cut from it (mm).

The build runs a :class:`Recipe` as two B-rep booleans (:meth:`Recipe.solid`); the design page's preview runs the
same recipe as mesh booleans on each tool's mesh, kept between edits by the tool's call (:class:`Tool` is its
own key), so an edit to one cap re-meshes only the tools made from that cap (:mod:`matcad.serve.preview`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable


@dataclass(frozen=True)
class Tool:
    """The solid, or the list of solids, ``make(*args)`` returns (mm). ``args`` are hashable values (numbers,
    strings, the spec's frozen dataclasses): equal tools make equal solids."""

    make: Callable[..., Any]
    args: tuple = ()

    def solids(self) -> list:
        made = self.make(*self.args)
        return list(made) if isinstance(made, (list, tuple)) else [made]


@dataclass(frozen=True)
class Recipe:
    """``stock`` fused with every solid of ``add`` in one boolean, then cut by every solid of ``cut`` in one."""

    stock: Tool
    add: tuple[Tool, ...] = ()
    cut: tuple[Tool, ...] = ()

    def solid(self):
        """The part as a build123d solid (mm)."""
        (part,) = self.stock.solids()
        if self.add:
            part = part.fuse(*(s for t in self.add for s in t.solids()))
        return part.cut(*(s for t in self.cut for s in t.solids()))
