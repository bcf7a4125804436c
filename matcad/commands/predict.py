"""`matcad predict SPEC`: every model's f0, the chosen f0 and its band; f(F) with ``--load``; a board's bands."""

from __future__ import annotations

from matcad.commands.common import check_fem_level, force_n, load_spec, note, print_json, spec_argument
from matcad.errors import EXIT_OK

HELP = "predict the taxel's resonance frequency from a spec"


def arguments(cmd) -> None:
    from matcad.acoustics.registry import model_choices

    spec_argument(cmd)
    cmd.add_argument("--load", type=force_n, nargs="+", metavar="F",
                     help="normal loads in N: f(F) from the cap mechanics ([mechanics]; FElupe) and, with a "
                          "[calibration], from paper Eq. 5 as well")
    cmd.add_argument("--force", dest="force_deprecated", type=force_n, nargs="+", metavar="F",
                     help="deprecated spelling of --load")
    cmd.add_argument("--model", choices=model_choices(),
                     help="use this model's f0 instead of the automatic choice ('fem' adds the FEM)")
    cmd.add_argument("--fem-level", type=int,
                     help="FEM mesh refinement: elements across the neck radius (default 8)")


def run(args) -> int:
    check_fem_level(args)
    if args.force_deprecated:
        note("predict --force is deprecated (it clashed with build --force); use --load")
    spec = load_spec(args.spec, args)
    forces = args.load or args.force_deprecated or ()
    from matcad.spec import is_array

    if spec.kind == "tube":
        return _tube(spec, forces, args)
    if is_array(spec):
        from matcad.prediction.board import predict_board

        from matcad.progress import line

        with line(f"predict {spec.name}", "taxels", quiet=args.json) as progress:
            result = predict_board(spec, forces, args.model, args.fem_level, progress)
        print_json(result.to_dict()) if args.json else print(result.to_text())
        return EXIT_OK
    from matcad.acoustics.design import design
    from matcad.prediction import predict

    from matcad.progress import line

    with line(f"predict {spec.name}", "steps", quiet=args.json) as progress:
        result = predict(spec, forces_n=forces, model=args.model, fem_level=args.fem_level, progress=progress)
    print_json(result.to_dict()) if args.json else print(result.to_text(spec.name, design(spec)))
    return EXIT_OK


def _tube(spec, forces, args) -> int:
    """A fipple tube's prediction (docs/tube.md): its own routes; ``--model fem [--fem-level N]`` adds the FEM
    rung (the axisymmetric exterior of a flanged or unflanged mouth, the 3-D window of a fipple), the MAT ladder's
    other models do not apply."""
    if args.model not in (None, "fem"):
        raise ValueError(f"--model {args.model} is a MAT taxel's model; a kind = 'tube' spec has its own routes "
                         "(docs/tube.md): leave it out, or --model fem for the FEM of its mouth")
    from matcad.acoustics.fem import DEFAULT_LEVEL
    from matcad.prediction.tube import predict_tube

    result = predict_tube(spec, forces, (args.fem_level or DEFAULT_LEVEL) if args.model == "fem" else None)
    print_json(result.to_dict()) if args.json else print(result.to_text())
    return EXIT_OK
