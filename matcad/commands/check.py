"""`matcad check SPEC`: the design rules, without building."""

from __future__ import annotations

from matcad.commands.common import load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK, EXIT_RULES

HELP = "run the design rules without building (exit 1 on errors)"


def arguments(cmd) -> None:
    spec_argument(cmd)


def run(args) -> int:
    from matcad.rules import check, errors, findings_text, verdict_dict

    findings = check(load_spec(args.spec, args))
    print_json(verdict_dict(findings)) if args.json else print(findings_text(findings))
    return EXIT_RULES if errors(findings) else EXIT_OK
