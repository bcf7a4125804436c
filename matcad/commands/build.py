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
