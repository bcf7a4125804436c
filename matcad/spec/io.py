"""Reading a spec: TOML files within size and nesting limits, a build's report.json, and ``--set`` overrides.

``--set key=value`` sets one dotted spec key (``neck.diameter=2.0``, ``wall.model=silicone``); the value is
parsed as TOML (``true``, ``[0.2, 0.6]``, ``"text"``) and, when it is not valid TOML, taken as a bare string.
The result is validated exactly like a file. A report.json written by ``matcad build`` carries the resolved
spec, so ``matcad build out/NAME/report.json --out again`` rebuilds the same kit. Lengths in the spec are mm.
"""

from __future__ import annotations

import copy
import re
import sys
import tomllib
from pathlib import Path
from typing import Any

from matcad.errors import InputError, shorten
from matcad.inputs import CALIBRATION_MAX_BYTES, SPEC_MAX_BYTES, read_text
from matcad.spec.calibration import Calibration
from matcad.spec.fields import MISSING, SpecError, read_section
from matcad.spec.measured import resolve_files
from matcad.spec.model import Spec, from_dict

MAX_NESTING = 32
"""Deepest TOML nesting a spec document may have (a spec needs 2); deeper is refused before Python recursion."""
REPORT_MAX_BYTES = 16 << 20
"""A report.json holds the spec plus the manifest and findings: allow more than a spec file."""


def load(path: str | Path) -> Spec:
    """Read and validate a spec TOML file (the files its [[measured]] tables name read too, relative to its folder).
    Raises SpecError naming the field on bad input."""
    return from_dict(with_measured_files(read_toml(path, "spec file", SPEC_MAX_BYTES), Path(path).parent))


def with_measured_files(data: dict, base_dir: Path) -> dict:
    """``data`` with the files its [[measured]] tables name (relative to ``base_dir``) turned into their numbers."""
    if "measured" not in data:
        return data
    return data | {"measured": resolve_files(data["measured"], base_dir)}


def load_calibration(path: str | Path) -> Calibration:
    """The [calibration] table of a calibration file or of a whole spec, validated like a spec's."""
    p = Path(path)
    data = read_toml(p, "calibration file", CALIBRATION_MAX_BYTES)
    if "cavity" in data:
        cal = from_dict(data).calibration
        if cal is None:
            raise SpecError("calibration", MISSING, f"is required: {p} has no [calibration] table")
        return cal
    if "calibration" not in data:
        raise SpecError("calibration", MISSING, f"is required: {p} has no [calibration] table")
    return read_section(Calibration, "calibration", data["calibration"])


def nesting_depth(value: Any, limit: int) -> int:
    """Nesting depth of parsed TOML data, stopping once it passes ``limit``."""
    if limit < 0 or not isinstance(value, (dict, list)):
        return 0
    items = value.values() if isinstance(value, dict) else value
    return 1 + max((nesting_depth(v, limit - 1) for v in items), default=0)


def read_toml(path: str | Path, what: str, limit: int) -> dict:
    """A size-limited regular file parsed as TOML; any failure is a SpecError naming the file (or the field)."""
    p = Path(path)
    try:
        text = read_text(p, what, limit)
    except InputError as exc:
        raise SpecError(what, str(p), str(exc).split(": ", 1)[-1]) from None
    return parse_toml(text, what, str(p))


_KEY_LINE = re.compile(r"^[ \t]*([A-Za-z0-9_.\"' -]+?)[ \t]*=[ \t]*[+-]?([0-9][0-9_]*)", re.M)
_TABLE_LINE = re.compile(r"^[ \t]*\[\[?[ \t]*([^\]]+?)[ \t]*\]", re.M)


def _long_integer(text: str) -> tuple[str, str, int] | None:
    """(dotted key, digits, line) of the first ``key = <integer>`` of ``text`` beyond Python's integer digit limit."""
    limit = sys.get_int_max_str_digits()
    for m in _KEY_LINE.finditer(text):
        digits = m.group(2).replace("_", "")
        if len(digits) > limit:
            tables = _TABLE_LINE.findall(text, 0, m.start())
            key = m.group(1).strip().strip("\"'")
            return (f"{tables[-1].strip()}.{key}" if tables else key), digits, text.count("\n", 0, m.start()) + 1
    return None


def parse_toml(text: str, what: str, where: str, value_of: str | None = None) -> dict:
    """``text`` parsed as TOML within the spec's limits (:data:`MAX_NESTING` levels, integers of at most
    ``sys.get_int_max_str_digits()`` digits). ``what`` and ``where`` (e.g. 'spec file' and its path) name it in
    the SpecError any failure raises; an over-long integer names its field (``value_of``: the field a one-line
    ``v = ...`` document stands for, as ``--set`` parses). Never a RecursionError or a traceback."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(what, where, f"must be valid TOML ({exc})") from None
    except RecursionError:
        raise SpecError(what, where, f"nests tables or arrays deeper than {MAX_NESTING} levels") from None
    except MemoryError:
        raise SpecError(what, where, "must be valid TOML within the parser's limits (out of memory)") from None
    except ValueError:  # an integer beyond Python's digit limit (int() refuses it before converting)
        limit = sys.get_int_max_str_digits()
        found = _long_integer(text)
        if found is None:
            raise SpecError(what, where, f"holds an integer of more than {limit} digits (no spec number has "
                                         "more than a few)") from None
        key, digits, line = found
        place = "" if value_of else f" ({what} {where}, line {line})"
        raise SpecError(value_of or key, digits, f"is an integer of {len(digits)} digits{place}: no spec number "
                                                 f"has more than a few, and Python reads at most {limit}") from None
    if nesting_depth(data, MAX_NESTING) > MAX_NESTING:
        raise SpecError(what, where, f"nests tables or arrays deeper than {MAX_NESTING} levels")
    return data


def read_spec_data(path: str | Path) -> dict:
    """The raw (unvalidated) spec data of a TOML file, or the resolved spec inside a build's report.json."""
    import json

    p = Path(path)
    if p.suffix.lower() != ".json":
        return with_measured_files(read_toml(p, "spec file", SPEC_MAX_BYTES), p.parent)
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
    """``key=value`` → (dotted key split, value parsed as TOML or else the bare string). The value obeys a spec
    file's limits (:data:`matcad.inputs.SPEC_MAX_BYTES`, :data:`MAX_NESTING`, the integer digit limit), and text
    after it (a newline and another key or table) is refused, never silently dropped."""
    key, sep, raw = text.partition("=")
    parts = key.strip().split(".")
    if not sep or not all(parts) or len(parts) > 2:
        raise SpecError("--set", text, "must be KEY=VALUE with KEY a spec field such as neck.diameter or name")
    raw, field = raw.strip(), ".".join(parts)
    what = f"--set {field}"
    if len(raw.encode("utf-8", "surrogatepass")) > SPEC_MAX_BYTES:
        raise SpecError(what, raw, f"is longer than a whole spec file may be ({SPEC_MAX_BYTES} bytes)")
    try:
        data = parse_toml(f"v = {raw}", what, raw, value_of=field)
    except SpecError as exc:
        if not exc.allowed.startswith("must be valid TOML"):  # a limit, not a bare word
            raise
        if "\n" in raw or "\r" in raw:
            raise SpecError(what, raw, "must be one value on one line; give each KEY=VALUE its own --set") from None
        return parts, raw
    if set(data) != {"v"}:
        tail = raw.replace("\r", "\n").split("\n", 1)[-1].strip()
        raise SpecError(what, raw, f"has text after its value ({shorten(tail)}); give each KEY=VALUE its own "
                                   "--set")
    return parts, data["v"]


def apply_sets(data: dict, assignments) -> dict:
    """A copy of ``data`` with every ``key=value`` of ``assignments`` set (validation is the caller's)."""
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


def load_spec(path: str | Path, assignments=()) -> tuple[Spec, dict]:
    """(validated Spec, the raw data it came from) for ``path`` with ``assignments`` applied."""
    data = apply_sets(read_spec_data(path), assignments)
    return from_dict(data), data
