"""Fabricated parts: one module per part, each a pure function of the validated spec (lengths in mm).

2-D (laser) parts return :class:`matcad.parts.flat.Flat` and never import a CAD kernel; 3-D (printed or cast)
parts import build123d inside their module, which `matcad.build` loads only when a 3-D output is asked for.
"""
