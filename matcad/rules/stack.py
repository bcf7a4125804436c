"""Rules for the assembled stack: needle clearance and placement, the flanges' seal, the riser, fasteners in printed
parts."""

from __future__ import annotations

from matcad.parts.features import needle_tip_mm
from matcad.parts.stack import mount_depth_mm, squeeze_range_mm
from matcad.rules.finding import Finding
from matcad.spec import cap_flange_thickness_mm, in_pocket

PAPER_THETA_DEG = (30.0, 75.0)
PAPER_Y_MM = (0.0, 3.47)
"""The paper's tested window (Sec. II): outside it the taxel may not sound."""
MAX_FLANGE_STRAIN = 0.3
"""Most compression a cast silicone flange should take: elastomer seals are designed for ~10-30 % squeeze
(O-ring practice, e.g. Parker O-Ring Handbook ORD 5700, static face seals); beyond it the silicone creeps."""


def needle_clearance(spec) -> list[Finding]:
    """The needle end must not touch the plate, and must still be held by the mount (the bore runs along
    the whole axis, so a tip standing inside the bore still has a clear jet path)."""
    n = spec.needle
    out = []
    if n.tip_clearance <= 0:
        out.append(Finding("needle.collision", "error", n.tip_clearance, "> 0",
                           "the needle end touches the neck plate", "set needle.tip_clearance > 0"))
    tip_z = needle_tip_mm(spec)[2]
    bottom = -mount_depth_mm(spec)
    if tip_z <= bottom:
        out.append(Finding("needle.collision", "error", round(-tip_z, 4), round(-bottom, 4),
                           f"the needle tip sits {-tip_z:.2f} mm below the plate, under the mount: nothing "
                           "holds it", "reduce needle.tip_clearance or raise theta"))
    return out


def needle_bore(spec) -> list[Finding]:
    """Every needle axis must pass through the mount block, or the printed mount has no bore and holds that
    needle (θ near 0, or |y| beyond the block). A taxel's axis meets the block's top face (z = −spacer.height) at
    x_top and its underside at x_bot; the block spans |x| <= plate.width/2 and |y| <= plate.depth/2 (mm)."""
    from matcad.parts.features import needle_axis_mm
    from matcad.spec import taxels

    board = taxels(spec)
    gap, depth, half = spec.spacer.height, mount_depth_mm(spec), spec.plate.width / 2
    out = []
    for t in board:
        (px, py, _), (ux, _, uz) = needle_axis_mm(t if len(board) > 1 else spec)
        run = ux / uz if uz > 0 else float("inf")  # x travelled per mm of descent along the axis
        x_top, x_bot = px - gap * run, px - depth * run
        if uz > 0 and x_bot <= half and x_top >= -half and abs(py) <= spec.plate.depth / 2:
            continue
        who = f"{t.name}: " if len(board) > 1 else ""
        out.append(Finding("needle.bore", "error", [t.needle.theta_deg, t.needle.y], f"axis through |x| <= {half:g} mm",
                           f"{who}the needle axis (theta = {t.needle.theta_deg:g} deg, y = {t.needle.y:g} mm) misses "
                           "the mount block: the mount would have no bore and hold no needle",
                           "raise needle.theta_deg or bring needle.y within the plate"))
    return out


def needle_window(spec) -> list[Finding]:
    out = []
    t, y = spec.needle.theta_deg, spec.needle.y
    if not PAPER_THETA_DEG[0] <= t <= PAPER_THETA_DEG[1]:
        out.append(Finding("needle.theta", "warning", t, list(PAPER_THETA_DEG),
                           f"theta = {t:g} deg is outside the paper's tested 30-75 deg; it may not sound",
                           "stay within 30-75 deg (paper chose 75)"))
    if not PAPER_Y_MM[0] <= y <= PAPER_Y_MM[1]:
        out.append(Finding("needle.y", "warning", y, list(PAPER_Y_MM),
                           f"y = {y:g} mm is outside the paper's tested 0-3.47 mm; it may not sound",
                           "stay within 0-3.47 mm"))
    return out


CALIPER_GUIDE = ("caliper the guide sheet BEFORE printing the mold, enter guide.thickness and set "
                 "guide.thickness_measured = true")
CALIPER_RISER = ("caliper the riser sheet BEFORE printing the mold, enter riser.thickness and set "
                 "riser.thickness_measured = true")


def _sheet_words(section) -> str:
    """How a sheet's thickness is known, in words: measured, a template's example value, or nominal."""
    if not section.thickness_measured:
        return "nominal, ISO 7823-1 cast sheet"
    return "an example value" if section.thickness_example else "measured"


def seal_squeeze(spec) -> list[Finding]:
    """The cap's flange must stay squeezed whatever the guide sheet really is, and not be crushed. A cap in a pocket
    of a [riser] (:func:`matcad.spec.in_pocket`) is squeezed over both the guide's and the riser's tolerance
    (:func:`matcad.parts.stack.squeeze_range_mm`). A template's example value (``guide.thickness_example``,
    ``riser.thickness_example``) is judged as the calipered sheet it stands for, and is reported unverified: the
    squeeze over the nominal sheets' tolerance, as a warning, until the user enters their own."""
    lo, hi, tol = squeeze_range_mm(spec)
    g = spec.guide
    flange = cap_flange_thickness_mm(spec)
    pocket = [spec.riser] if in_pocket(spec) else []
    example = any(s.thickness_measured and s.thickness_example for s in (g, *pocket))
    span = f"{lo:+.2f} … {hi:+.2f} mm over the guide sheet's ±{tol:.2f} mm ({g.thickness:g} mm {_sheet_words(g)})"
    if pocket:
        span = (f"{lo:+.2f} … {hi:+.2f} mm over the guide and riser sheets' ±{tol:.2f} mm ({g.thickness:g} mm "
                f"{_sheet_words(g)} + {spec.riser.thickness:g} mm {_sheet_words(spec.riser)}: the cap sits in a "
                "pocket of the riser)")
    if lo <= 0:
        fix = (CALIPER_GUIDE if not g.thickness_measured else
               CALIPER_RISER if pocket and not spec.riser.thickness_measured else
               f"raise end_cap.flange_squeeze above the {tol:g} mm measuring tolerance")
        return [Finding("seal.squeeze", "error" if spec.outputs.end_cap_mold else "warning", round(lo, 4), "> 0",
                        f"the {spec.end_cap.flange_squeeze:g} mm flange squeeze can be swallowed: squeeze {span}; "
                        "with a thick sheet the clamp never touches the flange and the cavity leaks", fix)]
    strain = hi / flange
    if strain > MAX_FLANGE_STRAIN:
        return [Finding("seal.squeeze", "warning", round(strain, 3), MAX_FLANGE_STRAIN,
                        f"the flange may be crushed by {100 * strain:.0f} % (squeeze {span})",
                        "reduce end_cap.flange_squeeze, or caliper the guide " + ("and riser sheets" if pocket
                                                                                  else "sheet"))]
    if example:
        n_lo, n_hi, n_tol = squeeze_range_mm(spec, nominal=True)
        named = [(name, s) for name, s in [("guide", g)] + [("riser", r) for r in pocket]
                 if s.thickness_measured and s.thickness_example]
        one = len(named) == 1
        nominal = "a nominal sheet's" if one else "nominal sheets'"
        return [Finding("seal.squeeze", "warning", [round(n_lo, 4), round(n_hi, 4)], "> 0",
                        "unverified: " + " and ".join(f"{n}.thickness = {s.thickness:g} mm" for n, s in named)
                        + (" is the template's example of a calipered sheet" if one else
                           " are the template's examples of calipered sheets")
                        + f", not yours; until you caliper {'it' if one else 'them'} the flange squeeze is "
                        f"{n_lo:+.2f} … {n_hi:+.2f} mm over {nominal} ±{n_tol:.2f} mm (ISO 7823-1): the clamp may "
                        f"never touch the flange (calipered, {lo:+.2f} … {hi:+.2f} mm)",
                        "; ".join({"guide": CALIPER_GUIDE, "riser": CALIPER_RISER}[n]
                                  + f" and {n}.thickness_example = false" for n, _ in named))]
    return [Finding("seal.squeeze", "info", [round(lo, 4), round(hi, 4)], "> 0",
                    f"flange squeeze {span}: {100 * lo / flange:.1f}-{100 * strain:.1f} % of the "
                    f"{flange:g} mm flange", "")]


def riser_idle(spec) -> list[Finding]:
    """A [riser] no taxel's neck runs on through (no ``neck.riser``) lengthens no neck: it only puts every cap in a
    pocket and thickens every flange by its thickness, a sheet to cut and bond for nothing (a warning)."""
    from matcad.spec import taxels

    if spec.riser is None or any(t.neck.riser for t in taxels(spec)):
        return []
    return [Finding("riser.idle", "warning", 0, ">= 1 neck through it",
                    f"riser: no taxel's neck runs on through the {spec.riser.thickness:g} mm riser, so it lengthens "
                    "none and only sets every cap in a pocket of it, its flange "
                    f"{spec.riser.thickness:g} mm thicker",
                    "set neck_riser = true on the taxels that need the longer neck ([[taxel]], or neck.riser), or "
                    "remove the [riser] table")]


def printed_fits(spec) -> list[Finding]:
    if spec.fasteners.dowel_fit_printed == "clearance":
        return [Finding("fit.dowel_printed", "warning", "clearance", "slip | press",
                        "clearance-fit dowels in the mount do not locate the stack", "use 'press' or 'slip'")]
    return []


RULES = (needle_clearance, needle_bore, needle_window, seal_squeeze, riser_idle, printed_fits)
TAXEL_RULES = (needle_clearance, needle_window, seal_squeeze)
"""The rules that read one taxel's own geometry: a board runs them on each taxel (:func:`matcad.rules.check`)."""
