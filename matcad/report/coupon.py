"""The coupon kit's small report (report.md and report.html): which coupon is which, each hole as finished and as
drawn (mm), the needle-mount sweep and the previews. Built from the same table as the kit's report.json."""

from __future__ import annotations


def coupon_markdown(table: dict) -> str:
    """``matcad coupon``'s report as Markdown from its report.json ``table`` (with ``figures``)."""
    lines = [f"# {table['name']} — test coupons", "",
             "Cut and print these first: measure each hole (pin gauges or the needle itself) and keep the size "
             "that fits as the spec's value (docs: README, fits and kerf).", "",
             "## Laser sheets", "", "| sheet | thickness [mm] | kerf [mm] |", "|---|---:|---:|"]
    lines += [f"| {name} | {s['thickness_mm']:g} | {s['kerf_mm']:g} |" for name, s in table["sheets"].items()]
    lines += ["", "## Laser holes (left to right)", "",
              "| part | purpose | finished [mm] | drawn [mm] | x, y [mm] |", "|---|---|---:|---:|---|"]
    lines += [f"| {h['part']} | {h['purpose']} | {h['finished_mm']:.3g} | {h['drawn_mm']:.3g} | "
              f"{h['x_mm']:.1f}, {h['y_mm']:.1f} |" for h in table["laser_holes"]]
    lines += ["", f"## Printed coupon ({table['printer']})", "",
              "| purpose | diameter [mm] | theta [deg] | x, y [mm] |", "|---|---:|---:|---|"]
    lines += [f"| {h['purpose']} | {h['diameter_mm']:.3g} | {h['theta_deg']:g} | {h['x_mm']:.1f}, {h['y_mm']:.1f} |"
              for h in table["printed_holes"]]
    if table["needle_sweep"]:
        lines += ["", "## Needle-mount sweep", "", "| file | varies | y [mm] | theta [deg] | notches |",
                  "|---|---|---:|---:|---:|"]
        lines += [f"| {s['file']} | {s['varies']} | {s['y_mm']:g} | {s['theta_deg']:g} | {s['notches']} |"
                  for s in table["needle_sweep"]]
    if table.get("figures"):
        lines += ["", "## Pictures", ""]
        for fig in table["figures"]:
            lines += ['<div class="picture">', "", f"### {fig['caption']}", "", f"![{fig['caption']}]({fig['file']})",
                      "", "</div>", ""]
    return "\n".join(lines).rstrip("\n") + "\n"
