"""Plots of the prediction (PNG): the band and its uncertainty budget, and the load curve f(F).

Both read the plain report data (``Prediction.to_dict()``), so they draw whatever the prediction carries.
"""

from __future__ import annotations

from pathlib import Path

BAND_PNG = "plot_band.png"
LOAD_PNG = "plot_load.png"


def chosen_model_status(p: dict) -> str:
    """'' when the prediction's chosen model holds for this design; else "chosen model NAME invalid (failed
    checks)". The one phrase the report's headline, the build's verdict line and the band chart share, so that a
    headline never says "pass" while the chart marks the chosen model invalid."""
    m = p.get("models", {}).get(p.get("model"))
    if m is None or m.get("valid", True):
        return ""
    failed = ", ".join(k for k, ok in m.get("checks", {}).items() if not ok)
    return f"chosen model {p['model']} invalid" + (f" ({failed})" if failed else "")


def chosen_models_status(r: dict) -> str:
    """:func:`chosen_model_status` of a report: a single taxel's; a board's names every taxel whose chosen model
    fails ("t1: chosen model elastic_wall invalid (no_wall_mode_near_f); t3: ..."), '' when all hold. The report's
    headline and the build's verdict line say this (a board's band chart is its first taxel's)."""
    board = r.get("taxels")
    if not board:
        return chosen_model_status(r["prediction"])
    return "; ".join(f"{t['name']}: {status}" for t in board if (status := chosen_model_status(t["prediction"])))


def band_plot(p: dict, path: Path) -> dict:
    """Every model's f0 (dot; cross when invalid), the chosen band (orange) and each budget line's shift (Hz) as a
    bar from f0 (blue), f0 dotted; drawn with :mod:`matcad.canvas` (no matplotlib on the build's path)."""
    from matcad.canvas import Canvas

    lines = p["budget"]
    f0, (lo, hi) = p["f0_hz"], p["band_hz"]
    labels = [b["source"] for b in reversed(lines)] + ["band (root-sum-square)"]
    labels += [f"{name}{' (chosen)' if name == p['model'] else ''}{'' if m['valid'] else ' (invalid)'}"
               for name, m in p["models"].items()]
    xs = [lo, hi, f0] + [f0 + b["low_hz"] for b in lines] + [f0 + b["high_hz"] for b in lines]
    xs += [m["f0_hz"] for m in p["models"].values() if m["f0_hz"] is not None]
    span = max(xs) - min(xs) or 1.0
    xlim = (min(xs) - 0.06 * span, max(xs) + 0.06 * span)
    status = chosen_model_status(p)
    title = f"f0 = {f0:.0f} Hz ({p['model']}), band {lo:.0f}–{hi:.0f} Hz" + (f"\n{status}" if status else "")
    top = 34 + (18 if status else 0)  # the status on a line of its own, so a long list of checks stays in
    height = top + 56 + 26 * len(labels)
    canvas = Canvas(792, height)
    left = 24 + max(canvas.text_width(label, 10) for label in labels)
    widest = max(canvas.text_width(line, 12) for line in title.splitlines())
    if left + widest > 792:  # the title, centred over the axes, would run off the right edge: widen the picture
        canvas = Canvas(round(left + widest), height)
    width = canvas.image.width
    ax = canvas.axes((left, top, width - 16, top + 6 + 26 * len(labels)), xlim, (-0.6, len(labels) - 0.4))
    y = 0
    for b in reversed(lines):
        ax.rect(f0 + b["low_hz"], y - 0.3, f0 + b["high_hz"], y + 0.3, fill="#8fb8e0")
        y += 1
    ax.rect(lo, y - 0.35, hi, y + 0.35, fill="#e08a3c")
    y += 1
    for m in p["models"].values():
        if m["f0_hz"] is not None:
            ax.marker(m["f0_hz"], y, "o" if m["valid"] else "x", "black")
        y += 1
    ax.line([f0, f0], list(ax.ylim), "#333333", 1, dash=3)
    ax.frame(xlabel="frequency [Hz]", yticks=list(enumerate(labels)), grid="x", title_colour="#a03000" if status
             else "black", title=title)
    canvas.save(path)
    return {"part": "prediction", "file": path.name, "caption": "models, band and uncertainty budget"}


def load_plot(p: dict, path: Path) -> dict | None:
    """f(F) from the prediction's load curve, one line per source (Eq. 5 calibration, cap mechanics) (N, Hz);
    None when no point has a value."""
    from matcad.canvas import TAB10, Canvas

    points = [pt for pt in p.get("load_curve", ()) if pt["f_hz"] is not None]
    if not points:
        return None
    sources = list(dict.fromkeys(pt.get("source", "Eq. 5") for pt in points))
    fs = [pt["f_hz"] for pt in points]
    forces = [pt["force_n"] for pt in points]
    fpad = 0.05 * (max(fs) - min(fs)) or 1.0
    xpad = 0.05 * (max(forces) - min(forces)) or 0.5
    canvas = Canvas(704, 396)
    ax = canvas.axes((80, 30, 690, 340), (min(forces) - xpad, max(forces) + xpad), (min(fs) - fpad, max(fs) + fpad))
    for k, source in enumerate(sources):
        mine = [pt for pt in points if pt.get("source", "Eq. 5") == source]
        ax.line([pt["force_n"] for pt in mine], [pt["f_hz"] for pt in mine], TAB10[k % 10], 2)
        for pt in mine:
            ax.marker(pt["force_n"], pt["f_hz"], "o", TAB10[k % 10], 2)
    ax.frame(xlabel="normal force F [N]", ylabel="f [Hz]", title="load curve f(F)", grid="xy")
    ax.legend([(source, TAB10[k % 10], "line") for k, source in enumerate(sources)])
    canvas.save(path)
    return {"part": "prediction", "file": path.name, "caption": "load curve f(F): " + "; ".join(sources)}
