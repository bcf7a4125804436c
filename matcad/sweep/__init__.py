"""Design sweeps: ``matcad sweep SPEC --vary FIELD=LO:HI:N ...`` → a table and design-space maps of f0, band,
sensitivity and rule verdicts over the full grid (docs/sweep.md).

grid.py (``--vary`` → variants) → fast.py (closed-form rungs on arrays) and tasks.py (one variant's predict,
rules, CAD as plain data) on executor.py (local processes or Dask) → run.py (the table) → outputs.py (files).
"""

from matcad.sweep.executor import Executor
from matcad.sweep.grid import MAX_GRID, MAX_POINTS, MAX_VARIANTS, Axis, parse_axes
from matcad.sweep.run import SweepResult, sweep

__all__ = ["Axis", "Executor", "MAX_GRID", "MAX_POINTS", "MAX_VARIANTS", "SweepResult", "parse_axes", "sweep"]
