"""`matcad build SPEC`: the fabrication kit and its report, written atomically into one folder."""

from __future__ import annotations

import sys

from matcad.commands.common import load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK, EXIT_RULES

HELP = "write the fabrication kit and report to out/<name>/"
OUT = "out/<name>"


def arguments(cmd) -> None:
    spec_argument(cmd)
    cmd.add_argument("--force", action="store_true", help="build despite design-rule errors")


def run(args) -> int:
    from matcad.build import DesignRuleFailure, build
    from matcad.progress import line

    spec = load_spec(args.spec, args)
    try:
        if spec.kind == "tube":
            return _tube(spec, args)
        with line(f"build {spec.name}", "stages", quiet=args.json) as progress:
            result = build(spec, out_dir=args.out, force=args.force, progress=progress)
    except DesignRuleFailure as exc:
        if args.json:
            print_json(exc.to_dict())
        else:
            print(exc.to_text())
            print(f"matcad: {exc.advice()}", file=sys.stderr)
        return EXIT_RULES
    print_json(result.to_dict()) if args.json else print(result.to_text(spec.name))
    return EXIT_OK


def _tube(spec, args) -> int:
    """A fipple tube's kit (:mod:`matcad.tube_build`)."""
    from matcad.tube_build import build_tube

    folder, report = build_tube(spec, out_dir=args.out, force=args.force)
    if args.json:
        print_json({"out": str(folder), "files": sorted(p.name for p in folder.iterdir()),
                    "f0_hz": report["prediction"]["f0_hz"], "band_hz": report["prediction"]["band_hz"]})
    else:
        print(f"{spec.name}: fipple tube kit in {folder}\n  f1 = {report['prediction']['f0_hz']:.0f} Hz, band "
              f"{report['prediction']['band_hz'][0]:.0f}-{report['prediction']['band_hz'][1]:.0f} Hz\n  files: "
              + ", ".join(sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))))
    return EXIT_OK
