"""Pictures for the report and the design page: part previews, plots, the dimensioned section.

Everything here draws headless with matplotlib's Agg backend, imported inside the functions that need it, so
that predict and the laser-only path stay light. Drawings are in mm; files are deterministic (no timestamps).
"""
