"""Where a spec comes from on the command line: a TOML file or a build's report.json, plus ``--set`` overrides.

``--set key=value`` sets one dotted spec key (``neck.diameter=2.0``, ``wall.model=silicone``); the value is
parsed as TOML (``true``, ``[0.2, 0.6]``, ``"text"``) and, when it is not valid TOML, taken as a bare string.
The result is validated exactly like a file. A report.json written by ``matcad build`` carries the resolved
spec, so ``matcad build out/NAME/report.json --out again`` rebuilds the same kit.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

REPORT_MAX_BYTES = 16 << 20
"""A report.json holds the spec plus the manifest and findings: allow more than a spec file."""


def read_spec_data(path: str | Path) -> dict:
    """The raw (unvalidated) spec data of a TOML file, or the resolved spec inside a build's report.json."""
    import json

    from matcad.errors import InputError
    from matcad.inputs import read_text
    from matcad.spec import SPEC_MAX_BYTES, SpecError, _read_toml

    p = Path(path)
    if p.suffix.lower() != ".json":
        return _read_toml(p, "spec file", SPEC_MAX_BYTES)
    try:
        report = json.loads(read_text(p, "report file", REPORT_MAX_BYTES))
    except InputError as exc:
        raise SpecError("report file", str(p), str(exc).split(": ", 1)[-1]) from None
    except (ValueError, RecursionError) as exc:
        raise SpecError("report file", str(p), f"must be valid JSON ({exc.__class__.__name__})") from None
    if not isinstance(report, dict) or not isinstance(report.get("spec"), dict):
        raise SpecError("report file", str(p), "must be a report.json written by `matcad build` (no \"spec\" table)")
    return report["spec"]


def parse_assignment(text: str) -> tuple[list[str], object]:
    """``key=value`` → (dotted key split, value parsed as TOML or else the bare string)."""
    from matcad.spec import SpecError

    key, sep, raw = text.partition("=")
    parts = key.strip().split(".")
    if not sep or not all(parts) or len(parts) > 2:
        raise SpecError("--set", text, "must be KEY=VALUE with KEY a spec field such as neck.diameter or name")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return parts, value


def apply_sets(data: dict, assignments) -> dict:
    """A copy of ``data`` with every ``key=value`` of ``assignments`` set (validation is the caller's)."""
    from matcad.spec import SpecError

    out = copy.deepcopy(data)
    for text in assignments or ():
        parts, value = parse_assignment(text)
        if len(parts) == 1:
            out[parts[0]] = value
            continue
        section = out.get(parts[0])
        if section is None:
            section = out[parts[0]] = {}
        if not isinstance(section, dict):
            raise SpecError(parts[0], section, f"must be a table to set {'.'.join(parts)}")
        section[parts[1]] = value
    return out


def load_spec(path: str | Path, assignments=()) -> tuple[object, dict]:
    """(validated Spec, the raw data it came from) for ``path`` with ``assignments`` applied."""
    from matcad.spec import from_dict

    data = apply_sets(read_spec_data(path), assignments)
    return from_dict(data), data
