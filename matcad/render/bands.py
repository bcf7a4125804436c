"""The band chart of a board: every taxel's unloaded and loaded band on one frequency axis, with the guard and the
2nd/3rd harmonics marked (PNG), and the same numbers as report data and a Markdown table. Frequencies Hz."""

from __future__ import annotations

from pathlib import Path

from matcad.render.figure import figure

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
    with figure(path, 7.6, 1.4 + 0.45 * len(rows)) as fig:
        ax = fig.add_subplot(1, 1, 1)
        harmonic_drawn = False
        for y, t in enumerate(reversed(rows)):
            (ul, uh), (ll, lh) = t["unloaded_hz"], t["loaded_hz"]
            ax.barh(y, uh - ul, left=ul, height=0.5, color="#5b8fc7", label="unloaded band" if y == 0 else None)
            ax.barh(y, lh - uh, left=uh, height=0.5, color="#e08a3c",
                    label=f"rise to {d['max_force_n']:g} N" if y == 0 else None)
            if ll < ul:
                ax.barh(y, ul - ll, left=ll, height=0.5, color="#e08a3c")
            for edge, width in ((ll - g, g), (lh, g)):
                ax.barh(y, width, left=edge, height=0.5, color="none", edgecolor="#777777", hatch="////",
                        linewidth=0.0, label="guard" if y == 0 and edge < ll else None)
            ax.plot([t["f0_hz"]], [y], marker="|", markersize=12, color="black")
            for n in d["harmonics"]:
                a, b = max(n * ll, lo), min(n * lh, hi)
                if a < b:  # only where it falls on the chart, i.e. near the bands
                    ax.barh(y - 0.32, b - a, left=a, height=0.14, color="#9b59b6", alpha=0.6,
                            label=None if harmonic_drawn else "harmonics of the loaded band")
                    ax.text(a, y - 0.32, f" {n}f", fontsize=6, va="center")
                    harmonic_drawn = True
        for c in d["conflicts"]:  # where the two (guarded) bands meet
            a, b = sorted((max(c["band_hz"][0], c["other_hz"][0]), min(c["band_hz"][1], c["other_hz"][1])))
            ax.axvspan(a - g / 2, b + g / 2, color="#d62728", alpha=0.25,
                       label="conflict" if c is d["conflicts"][0] else None)
        ax.set_yticks(range(len(rows)), [f"{t['name']} ({t['f0_hz']:.0f} Hz)" for t in reversed(rows)], fontsize=8)
        ax.set_xlim(lo, hi)
        ax.set_ylim(-0.8, len(rows) - 0.4)
        ax.set_xlabel("frequency [Hz]")
        verdict = f"{len(d['conflicts'])} conflict(s)" if d["conflicts"] else "disjoint"
        ax.set_title(f"{len(rows)} taxel band(s), guard {g:.0f} Hz, max force {d['max_force_n']:g} N: {verdict}",
                     fontsize=9, color="#b00000" if d["conflicts"] else "black")
        ax.grid(axis="x", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return {"part": "prediction", "file": path.name,
            "caption": "taxel bands: unloaded (blue), loaded rise (orange), guard (hatched), harmonics (purple)"}
