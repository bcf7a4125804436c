"""`matcad sweep SPEC --vary FIELD=LO:HI:N ...`: f0, band, sensitivities and rule verdicts over a grid."""

from __future__ import annotations

import os
from pathlib import Path

from matcad.commands.common import check_fem_level, load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK

HELP = "f0, band, sensitivity and rule verdicts over a grid of designs (table + maps)"
OUT = "out/<name>-sweep"
WORKERS = (1, 256)


def arguments(cmd) -> None:
    from matcad.acoustics.registry import model_choices

    spec_argument(cmd)
    cmd.add_argument("--vary", action="append", required=True, metavar="FIELD=LO:HI:N",
                     help="vary a numeric spec field over N evenly spaced values (or FIELD=a,b,c); repeat for a "
                          "full grid (e.g. --vary cavity.length=3:6:7 --vary neck.diameter=1.5,2.1)")
    cmd.add_argument("--model", choices=model_choices(),
                     help="model for every variant (default the spec's own choice; 'fem' adds the FEM)")
    cmd.add_argument("--fem-level", type=int, help="FEM mesh refinement with --model fem (default 8)")
    cmd.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                     help="local processes for the per-variant work (default one per CPU; 1 = in this process)")
    cmd.add_argument("--scheduler", metavar="ADDRESS", help="run the per-variant work on this Dask scheduler "
                                                            "(tcp://host:8786; needs matcad[cluster])")
    cmd.add_argument("--no-rules", action="store_true", help="skip the design rules (fast-model sweeps then "
                                                             "need no per-variant work)")
    cmd.add_argument("--table", default="csv", metavar="FORMAT",
                     help="the table's format: csv (default) or parquet (typed columns, ~10x faster to write a "
                          "large grid; needs matcad[parquet])")
    cmd.add_argument("--cad", action="store_true", help="also build each variant's end cap (build123d) and read "
                                                        "its STL volume back")


def run(args) -> int:
    from matcad.spec import apply_sets, read_spec_data
    from matcad.sweep import Executor, parse_axes, sweep
    from matcad.output import staged_output
    from matcad.progress import line
    from matcad.sweep.maps import Planes, write_maps
    from matcad.sweep.outputs import table_format, write_json
    from matcad.sweep.run import Block

    lo, hi = WORKERS
    if not lo <= args.workers <= hi:
        raise ValueError(f"--workers {args.workers} invalid, must be {lo}-{hi} local processes")
    check_fem_level(args)
    axes = parse_axes(args.vary)
    data = apply_sets(read_spec_data(args.spec), args.set)
    spec = load_spec(args.spec, args)  # validates the base spec (exit 2 naming the field) and prints its notes
    executor = Executor(args.workers, args.scheduler)
    writer = table_format(args.table)
    target = Path(args.out or Path("out") / f"{spec.name}-sweep")
    with staged_output(target) as tmp, line("sweep", "variants", quiet=args.json) as progress:
        table = writer(tmp, axes, not args.no_rules)  # the table streams into tmp; on an error nothing is left
        planes = Planes(axes, not args.no_rules)  # and what the maps show is kept from the same stream

        def sink(rows) -> None:
            block = Block.of(rows)
            table(block)
            planes(block)

        result = sweep(data, axes, model=args.model, executor=executor, rules=not args.no_rules, cad=args.cad,
                       fem_level=args.fem_level, sink=sink, progress=progress)
        files = table.close() + write_json(result, tmp, table.name) + write_maps(planes, tmp, result.model)
    if args.json:
        print_json(result.summary_dict(target, files))
    else:
        print(result.summary_text(target, files))
    return EXIT_OK
