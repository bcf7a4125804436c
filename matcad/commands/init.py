"""`matcad init NAME`: a new spec from a shipped template, its sources kept as comments; never overwrites."""

from __future__ import annotations

from pathlib import Path

from matcad.commands.common import print_json
from matcad.errors import EXIT_OK

HELP = "start a new spec from a shipped template (never overwrites)"


def arguments(cmd) -> None:
    cmd.add_argument("name", help="design name (also the file name NAME.toml and the build folder out/NAME)")
    cmd.add_argument("--from", dest="template", default="mat-paper",
                     help="template: mat-paper (default), mat-laser-only, mat-sla-array, mat-array-4")
    cmd.add_argument("--out", type=Path, help="spec file to write (default NAME.toml)")


def run(args) -> int:
    from matcad.init import new_spec

    try:
        path = new_spec(args.name, args.template, args.out)
    except FileExistsError as exc:
        raise ValueError(f"{exc.filename}: exists; refusing to overwrite it (choose another NAME or --out)") from None
    if args.json:
        print_json({"spec": str(path), "template": args.template})
    else:
        print(f"{path}: a copy of the {args.template} template named {args.name!r}; edit it, then "
              f"`matcad predict {path}` and `matcad build {path}`")
    return EXIT_OK
