"""`matcad coupon SPEC`: laser and printed test coupons that measure the user's own kerf and fits."""

from __future__ import annotations

from matcad.commands.common import load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK

HELP = "test coupons sweeping neck, dowel and needle-bore sizes"
OUT = "out/<name>-coupon"
WRITTEN = ("coupon_<sheet>.dxf/.svg, one per sheet with its kerf (engraved sizes), coupon_printed.stl/.step (needle "
           "bores at theta and dowel holes, ascending left to right), needle_mount_y*.stl (y sweep, notches on +x) "
           "and needle_mount_theta*.stl (theta sweep, notches on -x), preview_*.png; report.json, report.md and "
           "report.html list which is which")


def arguments(cmd) -> None:
    spec_argument(cmd)


def run(args) -> int:
    from matcad.build import build_coupon

    target, table = build_coupon(load_spec(args.spec, args), out_dir=args.out)
    if args.json:
        print_json({"out_dir": str(target), **table})
    else:
        print(f"coupons in {target}/: {WRITTEN}\nopen first: {target / 'report.html'}")
    return EXIT_OK
