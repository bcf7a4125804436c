"""`matcad calibrate DATA --spec S`: paper Eq. 5 fitted to measured force/frequency pairs, with uncertainty."""

from __future__ import annotations

from matcad.commands.common import load_spec, loop_output, note, print_json, spec_argument
from matcad.errors import EXIT_OK

HELP = "fit paper Eq. 5 to force/frequency pairs, with uncertainty"
OUT = "out/calibrate-<data>-<hash>"
CYCLE_STD_RANGE_N = (0.0, 100.0)


def arguments(cmd) -> None:
    cmd.add_argument("data", help="CSV with force_n and frequency_hz columns (and optionally cycle: several load "
                                  "cycles give the between-cycle variance)")
    spec_argument(cmd, "--spec", required=True)
    cmd.add_argument("--k-free", action="store_true", help="fix V0 to the as-built cavity and fit K instead")
    cmd.add_argument("--taxel", metavar="NAME", help="with an array spec: the taxel DATA was measured on (its own "
                                                     "geometry sets K or V0); give the result to sense as NAME=FILE")
    cmd.add_argument("--temperature-c", type=float, help="air temperature during calibration (degC; default the "
                                                         "spec's [air] temperature_c), recorded for `sense`")
    cmd.add_argument("--cycle-std-n", type=float, help="between-cycle (hysteresis) sd in N assumed when DATA holds "
                                                       "one load cycle (default 0.7, from the paper's ~1 N)")


def one_taxel(spec, name):
    """The single-taxel spec of taxel ``name`` of an array (a calibration is one taxel's); a one-taxel spec as is."""
    from matcad.spec import taxel_spec, taxels

    board = taxels(spec)
    names = ", ".join(t.name for t in board)
    if name is None:
        if len(board) > 1:
            raise ValueError(f"{spec.name} has {len(board)} taxels: calibrate one at a time with --taxel NAME, NAME "
                             f"one of {names}")
        return spec
    match = [t for t in board if t.name == name]
    if not match:
        raise ValueError(f"--taxel {name!r} invalid, must be one of {names}")
    return taxel_spec(spec, match[0])


def run(args) -> int:
    from matcad.acoustics.eq5 import TEMPERATURE_RANGE_C
    from matcad.loop import outputs
    from matcad.loop.calibrate import fit_from_spec, plot, read_csv
    from matcad.output import staged_output
    from matcad.spec import frequency_notes

    spec = one_taxel(load_spec(args.spec, args), args.taxel)
    lo, hi = TEMPERATURE_RANGE_C
    if args.temperature_c is not None and not lo <= args.temperature_c <= hi:
        raise ValueError(f"--temperature-c {args.temperature_c:g} invalid, must be {lo:g} to {hi:g} degC")
    lo, hi = CYCLE_STD_RANGE_N
    if args.cycle_std_n is not None and not lo <= args.cycle_std_n <= hi:
        raise ValueError(f"--cycle-std-n {args.cycle_std_n:g} invalid, must be {lo:g}-{hi:g} N")
    forces, freqs, cycles = read_csv(args.data)
    for text in frequency_notes(freqs, f"{args.data} frequency_hz"):
        note(text)
    fitted = fit_from_spec(forces, freqs, spec, k_free=args.k_free, cycles=cycles, temperature_c=args.temperature_c,
                           cycle_std_n=args.cycle_std_n)
    target = loop_output(args, "calibrate", str(args.data))
    with staged_output(target) as tmp:
        outputs.write_calibration_toml(fitted.law, tmp / "calibration.toml")
        if args.taxel is not None:  # the same table to paste under that [[taxel]] entry of the board spec
            outputs.write_calibration_toml(fitted.law, tmp / "taxel_calibration.toml", args.taxel, args.spec)
        plot(fitted, tmp / "residuals.png")
        outputs.write_json(tmp / "report.json", {"data": str(args.data), "spec": spec.name, **fitted.to_dict()})
    if args.json:
        print_json({**fitted.to_dict(), "out_dir": str(target)})
    else:
        print(fitted.to_text())
        extra = f"taxel_calibration.toml ([taxel.calibration] of {args.taxel}), " if args.taxel is not None else ""
        print(f"  calibration.toml, {extra}residuals.png in {target}/")
    return EXIT_OK
