"""One headless matplotlib figure → one deterministic PNG (no timestamps; same input, same bytes)."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

DPI = 110


@contextmanager
def figure(path: Path, width_in: float, height_in: float, **subplot_kw):
    """Yield (fig, axes) drawn with the Agg canvas; on exit save ``path`` as PNG and free the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width_in, height_in), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    yield fig
    # tight: a title or label longer than the figure widens the picture instead of being clipped at its edge
    fig.savefig(path, format="png", dpi=DPI, metadata={"Software": None}, bbox_inches="tight", pad_inches=0.06)
