"""The band chart of a board: every taxel's unloaded and loaded band on one frequency axis, with the guard and the
2nd/3rd harmonics marked (PNG), and the same numbers as report data and a Markdown table. Frequencies Hz."""

from __future__ import annotations

from pathlib import Path

BANDS_PNG = "plot_taxel_bands.png"


def bands_markdown(d: dict | None) -> list[str]:
    """The report's "Taxel bands" section from :func:`matcad.prediction.bands.summary`'s data."""
    if not d:
        return []
    lines = ["", "## Taxel bands", "",
             f"Loaded band = predicted band raised by f's rise up to {d['max_force_n']:g} N. Bands must stay "
             f"{d['guard_hz']:.0f} Hz apart (the loop's guard) and clear of each other's "
             f"{' and '.join(f'{n}f' for n in d['harmonics'])}.", "",
             "| taxel | x, y [mm] | f0 [Hz] | unloaded [Hz] | loaded [Hz] | rise | rise from |",
             "|---|---|---:|---:|---:|---:|---|"]
    lines += [f"| {t['name']} | {t['x_mm']:g}, {t['y_mm']:g} | {t['f0_hz']:.0f} | {t['unloaded_hz'][0]:.0f}–"
              f"{t['unloaded_hz'][1]:.0f} | {t['loaded_hz'][0]:.0f}–{t['loaded_hz'][1]:.0f} | "
              f"{100 * (t['rise'] - 1):+.1f} % | {t['rise_source']} |" for t in d["taxels"]]
    lines += ["", *(f"- **conflict:** {c['message']}" for c in d["conflicts"])] if d["conflicts"] else \
        ["", "No two bands (or a band and another's harmonic) come within the guard."]
    return lines


def band_chart(d: dict, path: Path) -> dict:
    """Draw :func:`matcad.prediction.bands.summary`'s data: one row per taxel with its unloaded band, the loaded rise on top, the
    guard either side (hatched), its 2f and 3f (light, where they fall near the bands) and any conflict in red."""
    rows = d["taxels"]
    lo = min(t["loaded_hz"][0] for t in rows) - 3 * d["guard_hz"]
    hi = max(t["loaded_hz"][1] for t in rows) + 3 * d["guard_hz"]
    if len(rows) > 1:  # show the lowest band's 2f: where the harmonic rule bites first
        hi = max(hi, min(d["harmonics"]) * min(t["loaded_hz"][1] for t in rows) + 3 * d["guard_hz"])
    span = hi - lo
    lo, hi = lo - 0.05 * span, hi + 0.05 * span
    g = d["guard_hz"]
    from matcad.canvas import Canvas

    names = [f"{t['name']} ({t['f0_hz']:.0f} Hz)" for t in reversed(rows)]
    canvas = Canvas(836, 154 + 50 * len(rows))
    left = 24 + max(canvas.text_width(n, 10) for n in names)
    legend = [("unloaded band", "#5b8fc7", "bar"), (f"rise to {d['max_force_n']:g} N", "#e08a3c", "bar"),
              ("guard", "#777777", "hatch")]
    right = 836 - 16 - max(canvas.text_width(label, 9) for label in
                           [e[0] for e in legend] + ["harmonics of the loaded band"]) - 34
    ax = canvas.axes((left, 34, right, 100 + 50 * len(rows)), (lo, hi), (-0.8, len(rows) - 0.4))
    harmonic_drawn = False
    for y, t in enumerate(reversed(rows)):
        (ul, uh), (ll, lh) = t["unloaded_hz"], t["loaded_hz"]
        ax.rect(ul, y - 0.25, uh, y + 0.25, fill="#5b8fc7")
        ax.rect(uh, y - 0.25, lh, y + 0.25, fill="#e08a3c")
        if ll < ul:
            ax.rect(ll, y - 0.25, ul, y + 0.25, fill="#e08a3c")
        for edge, width in ((ll - g, g), (lh, g)):
            ax.rect(max(edge, lo), y - 0.25, min(edge + width, hi), y + 0.25, hatch="#777777")
        ax.marker(t["f0_hz"], y, "|", "black", 6)
        for n in d["harmonics"]:
            a, b = max(n * ll, lo), min(n * lh, hi)
            if a < b:  # only where it falls on the chart, i.e. near the bands
                ax.rect(a, y - 0.39, b, y - 0.25, fill="#c39bd3")
                ax.text(a, y - 0.32, f" {n}f", 8, anchor="lm")
                harmonic_drawn = True
    for c in d["conflicts"]:  # where the two (guarded) bands meet
        a, b = sorted((max(c["band_hz"][0], c["other_hz"][0]), min(c["band_hz"][1], c["other_hz"][1])))
        ax.rect(max(a - g / 2, lo), ax.ylim[0], min(b + g / 2, hi), ax.ylim[1], outline="#d62728", width=3)
    verdict = f"{len(d['conflicts'])} conflict(s)" if d["conflicts"] else "disjoint"
    ax.frame(xlabel="frequency [Hz]", yticks=list(enumerate(names)), grid="x", size=11,
             title=f"{len(rows)} taxel band(s), guard {g:.0f} Hz, max force {d['max_force_n']:g} N: {verdict}",
             title_colour="#b00000" if d["conflicts"] else "black")
    legend += [("harmonics of the loaded band", "#c39bd3", "bar")] if harmonic_drawn else []
    legend += [("conflict", "#d62728", "line")] if d["conflicts"] else []
    ax.legend(legend, outside=True)
    canvas.save(path)
    return {"part": "prediction", "file": path.name,
            "caption": "taxel bands: unloaded (blue), loaded rise (orange), guard (hatched), harmonics (purple)"}
