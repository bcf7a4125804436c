"""`matcad design SPEC`: one taxel solved onto a target f0, or N taxels onto disjoint bands; writes a spec."""

from __future__ import annotations

import sys
from pathlib import Path

from matcad.commands.common import load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK, EXIT_RULES

HELP = "solve a taxel for a target f0, or N taxels for disjoint bands; writes a spec"
OUT = "out/<name>-design"


def arguments(cmd) -> None:
    spec_argument(cmd)
    cmd.add_argument("--target-hz", type=float, metavar="F", help="target unloaded f0 (Hz) of one taxel")
    cmd.add_argument("--vary", nargs="+", metavar="FIELD[=LO:HI]",
                     help="fields the solver may change: neck.diameter, cavity.diameter, cavity.length (optional "
                          "range in mm), neck.length (the plate's stock sheet) and, with a [riser], neck.riser (each "
                          "taxel's neck through the riser or its cap in a pocket of it: the way needing the least "
                          "change of the others); with --taxels default neck.diameter")
    cmd.add_argument("--taxels", type=int, metavar="N", help="design an array of N taxels with disjoint bands")
    cmd.add_argument("--band", type=float, nargs=2, metavar=("LO", "HI"),
                     help="with --taxels: the band (Hz) they share")
    cmd.add_argument("--name", help="name of the written spec (default <name>-<F>hz or <name>-<N>taxels)")


def solve(spec, args):
    """The design the arguments ask for: a :class:`matcad.design.solve.Solution` (one taxel onto --target-hz) or
    an :class:`matcad.design.allocate.Allocation` (--taxels N in --band LO HI)."""
    import dataclasses

    from matcad.design.solve import parse_vary

    if spec.kind == "tube":
        return _tube(spec, args)
    if (args.target_hz is None) == (args.taxels is None):
        raise ValueError("design needs either --target-hz F (one taxel) or --taxels N --band LO HI (an array)")
    if args.target_hz is not None:
        from matcad.design.solve import solve as solve_one

        if args.band:
            raise ValueError("--band goes with --taxels, not with --target-hz")
        if not args.vary:
            raise ValueError("--target-hz needs --vary FIELD [FIELD ...] (the fields the solver may change)")
        result = solve_one(spec, args.target_hz, parse_vary(spec, args.vary))
        return dataclasses.replace(result, spec=dataclasses.replace(
            result.spec, name=args.name or f"{spec.name}-{args.target_hz:.0f}hz"))
    from matcad.design.allocate import allocate
    from matcad.progress import line

    if not args.band:
        raise ValueError("--taxels needs --band LO HI (Hz)")
    vary = parse_vary(spec, args.vary or ["neck.diameter"])  # allocate says which fields a board may vary
    with line(f"design {spec.name}", "taxels", quiet=args.json) as progress:
        return allocate(spec, args.taxels, *args.band, vary, args.name, progress)


def _tube(spec, args):
    """A tube spec: its length solved onto --target-hz (:mod:`matcad.design.tube`)."""
    from matcad.design.tube import solve_tube

    if args.target_hz is None or args.taxels is not None or args.band:
        raise ValueError("a kind = 'tube' spec is designed with --target-hz F alone (--taxels/--band are MAT boards)")
    if args.vary and list(args.vary) != ["tube.length"]:
        raise ValueError(f"--vary {' '.join(args.vary)}: a tube design varies tube.length only")
    return solve_tube(spec, args.target_hz, args.name or f"{spec.name}-{args.target_hz:.0f}hz")


def run(args) -> int:
    from matcad.design import RulesFailed
    from matcad.design.spec_toml import write_design
    from matcad.rules import errors, findings_text

    spec = load_spec(args.spec, args)
    try:
        result = solve(spec, args)
    except RulesFailed as exc:
        if args.json:
            print_json({"verdict": "fail", "error": str(exc), "findings": [f.to_dict() for f in exc.findings]})
        else:
            print(findings_text(errors(exc.findings)))
        print(f"matcad: {exc}; nothing written", file=sys.stderr)
        return EXIT_RULES
    target = args.out or Path("out") / f"{result.spec.name}-design"
    report = {"source": str(args.spec), **result.to_dict()}
    files = write_design(target, result.spec, report, f"written by `matcad design` from {args.spec}",
                         picture=None if spec.kind == "tube" else lambda folder: picture(spec, result, folder))
    if args.json:
        print_json({**report, "out_dir": str(target), "spec_file": str(target / f"{result.spec.name}.toml"),
                    "written": files})
    else:
        print(result.to_text())
        warnings = [f for f in result.findings if f.level == "warning"]
        if warnings:  # what `matcad check` would warn of on the written spec
            print(findings_text(warnings))
        print(f"  {', '.join(files)} in {target}/")
    return EXIT_OK


def picture(start, result, folder: Path) -> str:
    """The design's picture in ``folder``: a solved taxel's f0 curve and section, or an array's band chart (a tube's
    design draws none yet: its f1 against tube.length is printed)."""
    from matcad.design.picture import allocation_chart, solution_plot

    if hasattr(result, "bands"):
        return allocation_chart(result, folder)
    return solution_plot(start, result, folder)
