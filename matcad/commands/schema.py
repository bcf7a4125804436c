"""`matcad schema`: every spec field with its unit, default, allowed range and meaning."""

from __future__ import annotations

from matcad.commands.common import print_json
from matcad.errors import EXIT_OK

HELP = "print every spec field with unit, default and allowed range (--json: a JSON Schema for editors)"


def arguments(cmd) -> None:
    cmd.add_argument("--rows", action="store_true",
                     help="with --json: the field table as rows (key, unit, default, allowed, ...) instead of the "
                          "JSON Schema")


def run(args) -> int:
    from matcad.spec import schema, schema_text
    from matcad.spec.json_schema import json_schema

    rows = schema()
    if args.json:
        print_json(rows if args.rows else json_schema(rows))
    else:
        print(schema_text(rows))
    return EXIT_OK
