"""Generated specs through `check` and `build`: never a traceback, never a partial or out-of-place folder;
invalid → exit 2 naming the field; valid → every output reads back. CI runs a bounded number;
benchmarks/fuzz.py runs ≥ 10 000."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from matcad import spec as spec_mod
from matcad.cli import main
from tests.conftest import PAPER
from tests.readback import assert_build_folder

BASE = tomllib.loads(PAPER.read_text())
LASER_ONLY = {"end_cap_mold": False, "needle_mount": False, "assembly": False}

weird_value = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6), st.booleans(),
    st.text(max_size=6), st.lists(st.floats(-10, 10), max_size=3), st.just(1e300), st.just(-0.0), st.just(1e-9))
name_value = st.one_of(st.sampled_from(["ok", "a.b-c_d", "../escape", "/abs", "a/b", "..", ".", "", "x" * 70,
                                        "con", "naïve", "日本", "a\\b", "-dash", " space"]),
                       st.text(max_size=12))


def _scaled(value, factor):
    return value * factor if isinstance(value, float) else value


@st.composite
def spec_documents(draw):
    """A spec document: the paper's, perturbed field by field with valid, borderline and invalid values."""
    data = json.loads(json.dumps(BASE))
    data["outputs"] = dict(LASER_ONLY) if draw(st.integers(0, 9)) else {}
    fields = [(s, k) for s, table in data.items() if isinstance(table, dict) for k in table if s != "outputs"]
    for section, key in draw(st.lists(st.sampled_from(fields), max_size=3, unique=True)):
        value = data[section][key]
        mode = draw(st.sampled_from(["scale", "weird", "delete"]))
        if mode == "scale":
            data[section][key] = _scaled(value, draw(st.sampled_from([0.1, 0.5, 0.9, 1.1, 2.0, 10.0, 1e3])))
        elif mode == "weird":
            data[section][key] = draw(weird_value)
        else:
            del data[section][key]
    if draw(st.booleans()):
        data["name"] = draw(name_value)
    if draw(st.integers(0, 19)) == 0:
        data[draw(st.sampled_from(["cavty", "outputs", "x"]))] = {"y": 1}
    return data


def to_toml(data: dict) -> str:
    def value(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float):
            return "nan" if math.isnan(v) else ("inf" if v == math.inf else "-inf" if v == -math.inf else repr(v))
        if isinstance(v, int):
            return str(v)
        if isinstance(v, str):
            return json.dumps(v)
        return "[" + ", ".join(value(x) for x in v) + "]"
    lines = [f"name = {value(data['name'])}"] if "name" in data else []
    for section, table in data.items():
        if isinstance(table, dict):
            lines.append(f"[{section}]")
            lines += [f"{k} = {value(v)}" for k, v in table.items()]
        elif isinstance(table, list) and table and all(isinstance(t, dict) for t in table):  # [[taxel]]
            for entry in table:
                lines.append(f"[[{section}]]")
                lines += [f"{k} = {value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


def _tree(root: Path) -> dict:
    return {str(p.relative_to(root)): p.stat().st_size for p in sorted(root.rglob("*")) if p.is_file()}


def run_one(data: dict, workdir: Path, out_arg: str | None, force: bool) -> str:
    """Run check and build on one document; assert the contract; return the outcome class."""
    spec_path = workdir / "spec.toml"
    spec_path.write_text(to_toml(data), encoding="utf-8")
    before = _tree(workdir)
    outcomes = []
    for argv in (["check", str(spec_path)],
                 ["build", str(spec_path)] + (["--out", out_arg] if out_arg else []) + (["--force"] if force else [])):
        err, out = io.StringIO(), io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            code = main(argv)  # any exception escaping here is a traceback: the test fails
        assert code in (0, 1, 2), code
        if code == 2:  # one error line; a unit-slip note about a valid field may precede it
            lines = err.getvalue().strip().splitlines()
            errors = [line for line in lines if not line.startswith("matcad: note:")]
            assert len(errors) == 1 and "error" in errors[0], lines
        outcomes.append(code)
    after = _tree(workdir)
    leftovers = [p for p in workdir.rglob(".*tmp-*")] + [p for p in workdir.rglob(".*.old-*")]
    assert not leftovers, leftovers
    created = set(after) - set(before)
    code = outcomes[1]
    if code != 0:
        assert after == before, created  # a refused build writes nothing anywhere
        return {1: "rules", 2: "invalid"}[code]
    spec = spec_mod.load(spec_path)
    target = Path(out_arg) if out_arg else Path("out") / spec.name
    target = (workdir / target).resolve() if not target.is_absolute() else target
    assert target.is_dir() and str(target).startswith(str(workdir.resolve()))
    assert all(str((workdir / c).resolve()).startswith(str(target)) for c in created), created
    assert_build_folder(spec, target)
    return "built"


out_args = st.one_of(st.none(), st.sampled_from(["o", "nested/deeper/o", "o/../o2", "spec.toml", "out"]))


@given(data=spec_documents(), out_arg=out_args, force=st.booleans())
@example(data={**BASE, "air": {"temperature_c": 200.0}, "outputs": {}}, out_arg="spec.toml", force=False)  # CI run 28
@settings(max_examples=int(os.environ.get("MATCAD_FUZZ_EXAMPLES", "60")), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
def test_fuzz_check_and_build(tmp_path_factory, data, out_arg, force):
    workdir = tmp_path_factory.mktemp("fuzz")
    cwd = os.getcwd()
    os.chdir(workdir)
    try:
        run_one(data, workdir, out_arg, force)
    finally:
        os.chdir(cwd)


def test_garbage_files_are_exit_2(tmp_path):
    for blob in (b"\xff\xfe\x00garbage", b"name = 'x'\n[cavity\n", b"", "名前 = 1".encode()):
        path = tmp_path / "g.toml"
        path.write_bytes(blob)
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            assert main(["check", str(path)]) == 2
        assert len(err.getvalue().strip().splitlines()) == 1


@pytest.mark.parametrize("category", ["sets", "world", "serve", "sweep", "loop"])
def test_fuzz_categories_of_issue_21_hold(category, tmp_path):
    """A fast slice of benchmarks/fuzz.py's issue-21 categories (--set values, files from the user's world, the
    design server under hostile requests, sweep's --scheduler/--vary/--workers, the recording loop's float WAVs,
    short tones and cycle CSVs): every case keeps the contract (the benchmark runs hundreds)."""
    import random

    from benchmarks import fuzz

    breaches = []
    for case in fuzz.CATEGORIES[category](24, random.Random(21), tmp_path):
        try:
            case()
        except AssertionError as exc:  # fuzz.Breach is one
            breaches.append(str(exc)[:300])
    assert breaches == []
