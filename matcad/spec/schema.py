"""``matcad schema``: every spec field with its unit (mm for lengths), default, allowed values and meaning, read
from the one declaration of each field.
"""

from __future__ import annotations

import dataclasses

from matcad.spec.fields import allowed_text
from matcad.spec.measured import FILE_FIELDS
from matcad.spec.model import ARRAY_TABLES, REQUIRED_SECTIONS, SECTIONS, Spec


def schema() -> list[dict]:
    """Every spec field: key, unit, default, allowed values (as text, and as kind, choices, lo, hi) and meaning."""
    rows = []
    name_meta = dataclasses.fields(Spec)[0].metadata
    rows.append({"key": "name", "unit": "", "default": None, "allowed": "A-Z a-z 0-9 . _ - (1-64)",
                 "required": True, "doc": name_meta["doc"], "kind": "name", "choices": [], "lo": None,
                 "hi": None, "lo_open": True, "required_in_table": True})
    kind_meta = next(f for f in dataclasses.fields(Spec) if f.name == "kind").metadata
    rows.append({"key": "kind", "unit": "", "default": "mat", "allowed": allowed_text(dict(kind_meta)),
                 "required": False, "doc": kind_meta["doc"], "kind": "choice", "choices": list(kind_meta["choices"]),
                 "lo": None, "hi": None, "lo_open": True, "required_in_table": False})
    tables = [*SECTIONS.items(), *((f"{key}[]", cls) for key, cls in ARRAY_TABLES.items())]
    tables += [(f"{name}.{f.name}", f.metadata["section"]) for name, cls in tables for f in dataclasses.fields(cls)
               if f.metadata["kind"] == "section"]  # sub-tables, e.g. taxel[].calibration
    for section, cls in tables:
        for f in dataclasses.fields(cls):
            meta = f.metadata
            if meta["kind"] == "section":
                continue
            allowed = allowed_text(dict(meta))
            default = None if f.default is dataclasses.MISSING else f.default
            required = f.default is dataclasses.MISSING and section in REQUIRED_SECTIONS
            rows.append({"key": f"{section}.{f.name}", "unit": meta["unit"],
                         "default": list(default) if isinstance(default, tuple) else default,
                         "allowed": allowed, "required": required, "doc": meta["doc"], "kind": meta["kind"],
                         "choices": list(meta["choices"]), "lo": meta["lo"], "hi": meta["hi"],
                         "lo_open": meta["lo_open"], "required_in_table": f.default is dataclasses.MISSING})
    for key, (filled, doc) in FILE_FIELDS.items():  # read at load into the fields they fill
        rows.append({"key": f"measured[].{key}", "unit": "", "default": None,
                     "allowed": "a file path, relative to the spec's folder", "required": False,
                     "doc": f"instead of {' and '.join(filled)}: {doc}", "kind": "path", "choices": [], "lo": None,
                     "hi": None, "lo_open": True, "required_in_table": False})
    return rows


def schema_text(rows) -> str:
    """``matcad schema``'s text: per field its key, unit, default (or required), meaning and allowed values."""
    lines = []
    for row in rows:
        default = "(required)" if row["required"] else f"default {row['default']!r}"
        unit = f" [{row['unit']}]" if row["unit"] else ""
        lines.append(f"{row['key']}{unit}  {default}\n    {row['doc']}\n    allowed: {row['allowed']}")
    return "\n".join(lines)
