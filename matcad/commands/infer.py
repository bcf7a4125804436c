"""`matcad infer SPEC`: the as-built state of the lab that built the spec's [[measured]] taxels, with intervals,
what the data cannot tell apart, and this design's f0 built by that lab."""

from __future__ import annotations

from pathlib import Path

from matcad.commands.common import load_spec, print_json, spec_argument
from matcad.errors import EXIT_OK

HELP = "infer the as-built state (neck, joined air, sheet, silicone) from the spec's measured taxels"
OUT = "out/<name>-infer"


def arguments(cmd) -> None:
    spec_argument(cmd)


def state_toml(inference) -> str:
    """state.toml: the inferred state with 95 % intervals, and the data it rests on, as a TOML record."""
    lines = ["# as-built state inferred by `matcad infer` (docs/inference.md); values are the most probable,",
             "# low_95/high_95 their 95 % interval", f"model = \"{inference.model}\"",
             f"taxels = [{', '.join(repr(t.name).replace(chr(39), chr(34)) for t in inference.taxels)}]",
             f"data = {inference.data_count}", f"chi2 = {inference.chi2:.6g}", ""]
    for name, value, low, high in inference.intervals():
        lines += [f"[state.{name}]", f"value = {value:.6g}", f"low_95 = {low:.6g}", f"high_95 = {high:.6g}", ""]
    return "\n".join(lines)


def run(args) -> int:
    from matcad.loop.outputs import write_json
    from matcad.output import staged_output
    from matcad.prediction import predict
    from matcad.prediction.inference import infer
    from matcad.spec import is_array

    spec = load_spec(args.spec, args)
    inference = infer(spec)
    here = None if is_array(spec) else predict(spec, model="as_built", mechanics=False)
    target = args.out or Path("out") / f"{spec.name}-infer"
    report = {"spec": spec.name, **inference.to_dict()}
    if here is not None:
        report["this_design"] = {"f0_hz": here.f0_hz, "band_hz": list(here.band_hz),
                                 "physics_f0_hz": here.physics_f0_hz, "physics_model": here.physics_model}
    with staged_output(target) as tmp:
        (tmp / "state.toml").write_text(state_toml(inference), encoding="utf-8")
        write_json(tmp / "report.json", report)
    if args.json:
        print_json({**report, "out_dir": str(target)})
        return EXIT_OK
    print(inference.to_text())
    if here is not None:
        print(f"  {spec.name} built by this lab: f0 = {here.f0_hz:.0f} Hz, band {here.band_hz[0]:.0f}-"
              f"{here.band_hz[1]:.0f} Hz (physics only: {here.physics_f0_hz:.0f} Hz, {here.physics_model})")
    print(f"  state.toml, report.json in {target}/")
    return EXIT_OK
