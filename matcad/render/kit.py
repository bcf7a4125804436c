"""Every picture of one build, written into its folder: a preview per part, the band and load plots.

Returns the figure list the report embeds (file, caption, the part it shows). Laser parts are drawn from their
cut plans and printed parts from the STL just written, so the laser-only path loads neither the CAD kernel
nor a mesh library.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

LOAD_POINTS = 41
LOAD_FORCE_MAX_N = 20.0
"""Load curve drawn up to the calibration's measured range, else this (the paper loads to ~20 N), and never
past Eq. 5's V_eff minimum."""


def load_forces_n(spec) -> np.ndarray:
    """Forces (N) at which the build draws Eq. 5 f(F) for ``spec``'s calibration; empty without one (the cap
    mechanics' curve takes seconds and stays with ``matcad predict --load``)."""
    from matcad.acoustics.design import calibration

    cal = calibration(spec)
    if cal is None:
        return np.array([])
    lo, hi = spec.calibration.force_range_n or (0.0, LOAD_FORCE_MAX_N)
    hi = min(hi, cal.turn_force_n)
    return np.linspace(max(lo, 0.0), hi, LOAD_POINTS) if hi > max(lo, 0.0) else np.array([])


def render_figures(spec, prediction, folder: Path, meshes: dict, plans: list) -> list[dict]:
    """Write every preview and plot for ``spec`` into ``folder``; ``meshes`` names the STLs written (file →
    checks), ``plans`` are the laser parts' cut plans (:func:`matcad.parts.flat.cut_plan`) the build drew. Returns
    [{part, file, caption}] in report order: section, plots, laser parts, printed parts."""
    from matcad.prediction import predict
    from matcad.render.plots import BAND_PNG, LOAD_PNG, band_plot, load_plot
    from matcad.render.previews import flat_preview, preview_name, printed_preview
    from matcad.spec import taxel_spec, taxels

    figures = []
    board = taxels(spec)
    if (folder / "section.svg").is_file():  # a board's section is labelled, not dimensioned (write_section_svg)
        figures.append({"part": "assembly", "file": "section.svg", "caption": (
            "section through the neck and needle axes, dimensioned (mm)" if len(board) == 1 else
            f"section through {board[0].name}'s row of necks and the needle axes, parts labelled (mm; each "
            "taxel's sizes: Taxels)")})
    first = taxel_spec(spec, board[0])  # ``prediction`` is the first taxel's; the band chart shows every taxel
    scope = f" (taxel {board[0].name} of {len(board)})" if len(board) > 1 else ""
    figure = band_plot(prediction.to_dict(), folder / BAND_PNG)
    figures.append(figure | {"caption": figure["caption"] + scope})
    forces = load_forces_n(first)
    if len(forces):
        figure = load_plot(predict(first, forces_n=forces, mechanics=False).to_dict(), folder / LOAD_PNG)
        if figure:
            figures.append(figure)
    for plan in plans:
        figures.append(flat_preview(plan, folder / preview_name(plan.flat.name)))
    for stl in sorted(meshes):
        name = Path(stl).stem
        figures.append(printed_preview(name, folder / stl, folder / preview_name(name)))
    return figures
