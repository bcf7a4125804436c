"""The picture of `matcad design --target-hz`: the target, f0 along the varied field, and the taxel's section as it
was and as solved (PNG). Lengths mm, frequencies Hz. The data are plain (the design app computes them)."""

from __future__ import annotations

from pathlib import Path

from matcad.render.figure import figure

DESIGN_PNG = "plot_design.png"


def _section(ax, g: dict, style: dict, label: str) -> None:
    """A taxel's axial half-section from its geometry ``g`` (cavity D, L; neck d, l; mm): the neck through the
    plate from z = 0 down to -l, the cavity above it to L."""
    D, L, d, l = g["cavity.diameter"], g["cavity.length"], g["neck.diameter"], g["neck.length"]
    xs = [-d / 2, -d / 2, -D / 2, -D / 2, D / 2, D / 2, d / 2, d / 2]
    zs = [-l, 0, 0, L, L, 0, 0, -l]
    ax.plot(xs, zs, label=label, **style)


def design_plot(d: dict, path: Path) -> dict:
    """Two panels from ``d``: f0 (Hz) along the first varied field (``curve``: [[value mm, f0 Hz], ...]) with the
    target, the start and the solution marked; the section of the start and the solved geometry (``start``,
    ``solved``: {field: mm} for cavity.diameter/length and neck.diameter/length) with their dimensions."""
    field = d["field"]
    with figure(path, 8.4, 3.6) as fig:
        ax, bx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.4, 1]})
        xs, fs = zip(*d["curve"]) if d["curve"] else ((), ())
        ax.plot(xs, fs, color="#1f4e8c", lw=1.5, label=f"f0 by {d['model']}")
        ax.axhline(d["target_hz"], color="#c0392b", lw=1, ls="--", label=f"target {d['target_hz']:g} Hz")
        ax.plot([d["start"][field]], [d["start_f0_hz"]], "o", mfc="white", mec="#555555", label="start")
        ax.plot([d["solved"][field]], [d["f0_hz"]], "o", color="#c0392b",
                label=f"solved: {d['solved'][field]:.4g} mm, {d['f0_hz']:.1f} Hz")
        ax.set(xlabel=f"{field} [mm]", ylabel="f0 [Hz]")
        ax.set_title(f"{d['name']}: f0 onto {d['target_hz']:g} Hz (error {100 * d['error']:+.3f} %)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        _section(bx, d["start"], {"color": "#888888", "ls": "--", "lw": 1}, "start")
        _section(bx, d["solved"], {"color": "#1f4e8c", "lw": 1.8}, "solved")
        s = d["solved"]
        bx.annotate(f"D {s['cavity.diameter']:.3g}", (0, s["cavity.length"]), xytext=(0, 3),
                    textcoords="offset points", ha="center", fontsize=7)
        bx.annotate(f"L {s['cavity.length']:.3g}", (s["cavity.diameter"] / 2, s["cavity.length"] / 2),
                    xytext=(3, 0), textcoords="offset points", fontsize=7)
        bx.annotate(f"d {s['neck.diameter']:.3g}, l {s['neck.length']:.3g}", (s["neck.diameter"] / 2,
                    -s["neck.length"] / 2), xytext=(4, 0), textcoords="offset points", fontsize=7, va="center")
        bx.set_aspect("equal")
        bx.set(xlabel="r [mm]", ylabel="z [mm]")
        bx.set_title("section: start (dashed) and solved", fontsize=9)
        bx.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    return {"file": path.name, "caption": f"{d['name']}: f0 against {field}, target and solved section"}
