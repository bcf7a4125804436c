"""Plots of the prediction (PNG): the band and its uncertainty budget, and the load curve f(F).

Both read the plain report data (``Prediction.to_dict()``), so they draw whatever the prediction carries.
"""

from __future__ import annotations

from pathlib import Path

from matcad.render.figure import figure

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


def band_plot(p: dict, path: Path) -> dict:
    """Every model's f0, the chosen band, and each budget line's shift (Hz) as a bar from f0."""
    lines = p["budget"]
    f0, (lo, hi) = p["f0_hz"], p["band_hz"]
    with figure(path, 7.2, 1.2 + 0.32 * (len(lines) + len(p["models"]) + 1)) as fig:
        ax = fig.add_subplot(1, 1, 1)
        labels, y = [], 0
        for b in reversed(lines):
            ax.barh(y, b["high_hz"] - b["low_hz"], left=f0 + b["low_hz"], color="#8fb8e0", height=0.6)
            labels.append(b["source"])
            y += 1
        ax.barh(y, hi - lo, left=lo, color="#e08a3c", height=0.7)
        labels.append("band (root-sum-square)")
        y += 1
        for name, m in p["models"].items():
            ax.plot([m["f0_hz"]], [y], marker="o" if m["valid"] else "x", color="black")
            labels.append(f"{name}{' (chosen)' if name == p['model'] else ''}{'' if m['valid'] else ' (invalid)'}")
            y += 1
        ax.axvline(f0, color="#333333", linewidth=0.8, linestyle=":")
        ax.set_yticks(range(len(labels)), labels, fontsize=8)
        ax.set_xlabel("frequency [Hz]")
        status = chosen_model_status(p)
        ax.set_title(f"f0 = {f0:.0f} Hz ({p['model']}), band {lo:.0f}–{hi:.0f} Hz" + (f"\n{status}" if status else ""),
                     fontsize=10, color="#a03000" if status else "black")
        ax.grid(axis="x", alpha=0.3)
    return {"part": "prediction", "file": path.name, "caption": "models, band and uncertainty budget"}


def load_plot(p: dict, path: Path) -> dict | None:
    """f(F) from the prediction's load curve, one line per source (Eq. 5 calibration, cap mechanics) (N, Hz);
    None when no point has a value."""
    points = [pt for pt in p.get("load_curve", ()) if pt["f_hz"] is not None]
    if not points:
        return None
    sources = list(dict.fromkeys(pt.get("source", "Eq. 5") for pt in points))
    with figure(path, 6.4, 3.6) as fig:
        ax = fig.add_subplot(1, 1, 1)
        for source in sources:
            mine = [pt for pt in points if pt.get("source", "Eq. 5") == source]
            ax.plot([pt["force_n"] for pt in mine], [pt["f_hz"] for pt in mine], marker=".", label=source)
        ax.set_xlabel("normal force F [N]")
        ax.set_ylabel("f [Hz]")
        ax.set_title("load curve f(F)", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    return {"part": "prediction", "file": path.name, "caption": "load curve f(F): " + "; ".join(sources)}
