"""Pictures for the report and the design page: part previews, plots, the dimensioned section.

Everything here draws on :mod:`matcad.canvas` (Pillow; PNG) or writes SVG itself, never with matplotlib, so that
a build stays near the cost of its imports (issue 25). Drawings are in mm; files are deterministic (no
timestamps).
"""
