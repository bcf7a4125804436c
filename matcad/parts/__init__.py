"""Fabricated parts: one module per part, each a pure function of the validated spec (lengths in mm).

Each part module declares its parts in a ``PARTS`` tuple that :mod:`matcad.parts.registry` discovers (see
docs/extending.md). 2-D (laser) parts return :class:`matcad.parts.flat.Flat` and never import a CAD kernel;
3-D (printed or cast) parts import build123d inside the functions that make solids, so discovering them costs
nothing and `matcad.build` loads the kernel only when a 3-D output is asked for.
"""
