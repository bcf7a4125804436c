"""`matcad schema`: every spec field with its unit, default, allowed range and meaning."""

from __future__ import annotations

from matcad.commands.common import print_json
from matcad.errors import EXIT_OK

HELP = "print every spec field with unit, default and allowed range"


def arguments(cmd) -> None:
    """No arguments beyond --json."""


def run(args) -> int:
    from matcad.spec import schema, schema_text

    rows = schema()
    if args.json:
        print_json(rows)
    else:
        print(schema_text(rows))
    return EXIT_OK
