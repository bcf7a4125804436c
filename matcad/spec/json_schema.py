"""The spec as a JSON Schema (draft 2020-12), made from :func:`matcad.spec.schema.schema`'s rows.

Editors validate and complete a TOML spec with it (Taplo / Even Better TOML: a ``#:schema`` line at the top of the
file, or a ``.taplo.toml`` rule; docs in README "Editor support"). It says what the spec's loader checks field by
field: types, units (in each description), bounds (``minimum``/``exclusiveMinimum``/``maximum``), choices (``enum``),
defaults, the required fields and tables, and that unknown keys are refused (``additionalProperties: false``).
What it cannot say (a range's low <= high, the checks across fields such as a neck narrower than its cavity) is
left to ``matcad check``: the schema accepts a few specs the loader then refuses, never the reverse.
"""

from __future__ import annotations

DIALECT = "https://json-schema.org/draft/2020-12/schema"
ID = "https://github.com/matcad/matcad/spec.schema.json"
NAME_PATTERN = "^(?!\\.{1,2}$)[A-Za-z0-9][A-Za-z0-9._-]{0,63}$"
TEXT_PATTERN = "^[ -~]{0,40}$"


def _bounded(row: dict, json_type: str = "number") -> dict:
    out: dict = {"type": json_type}
    if row["lo"] is not None:
        out["exclusiveMinimum" if row["lo_open"] else "minimum"] = row["lo"]
    if row["hi"] is not None:
        out["maximum"] = row["hi"]
    return out


def field_schema(row: dict) -> dict:
    """The JSON Schema of one field row (its kind, bounds, choices, default and meaning with its unit)."""
    kind = row["kind"]
    if kind == "number":
        out = _bounded(row)
    elif kind == "integer":
        out = _bounded(row, "integer")
    elif kind == "bool":
        out = {"type": "boolean"}
    elif kind == "choice":
        out = {"enum": list(row["choices"])}
    elif kind == "range":
        out = {"type": "array", "items": _bounded(row), "minItems": 2, "maxItems": 2}
    elif kind == "vector":
        out = {"type": "array", "items": _bounded(row), "minItems": 1, "maxItems": 10000}
    elif kind == "vector9":
        out = {"type": "array", "items": _bounded(row), "minItems": 9, "maxItems": 9}
    elif kind == "name":
        out = {"type": "string", "pattern": NAME_PATTERN}
    elif kind == "text":
        out = {"type": "string", "pattern": TEXT_PATTERN}
    else:  # path
        out = {"type": "string", "minLength": 1}
    unit = f" [{row['unit']}]" if row["unit"] else ""
    out["description"] = f"{row['doc']}{unit}; allowed: {row['allowed']}"
    if row["default"] is not None:
        out["default"] = row["default"]
    return out


def _table() -> dict:
    return {"type": "object", "properties": {}, "additionalProperties": False}


def json_schema(rows=None) -> dict:
    """The whole spec's JSON Schema (a dict, draft 2020-12) from ``rows`` (default :func:`schema`)."""
    from matcad.spec.schema import schema

    rows = schema() if rows is None else rows
    top = {"$schema": DIALECT, "$id": ID, "title": "matcad spec",
           "description": "A matcad spec (TOML): one MAT taxel, a board of them, or (kind = \"tube\") a fipple "
                          "tube taxel; lengths in mm. "
                          "`matcad schema` prints every field with its unit, default and range.",
           **_table(), "required": []}
    for row in rows:
        *tables, field = row["key"].split(".")
        node = top
        for name in tables:
            array = name.endswith("[]")
            name = name.removesuffix("[]")
            if name not in node["properties"]:
                node["properties"][name] = {"type": "array", "items": _table()} if array else _table()
            node = node["properties"][name]["items"] if array else node["properties"][name]
        node["properties"][field] = field_schema(row)
        if row["required_in_table"] and row["kind"] != "path":
            node.setdefault("required", []).append(field)
        if row["required"] and tables:  # a required field makes its table required at the top
            if tables[0] not in top["required"]:
                top["required"].append(tables[0])
    # kind = "tube" (docs/tube.md) needs its [tube] table instead of the MAT taxel's required tables
    mat_tables = [t for t in top["required"] if t != "name"]
    top["required"] = [t for t in top["required"] if t not in mat_tables]
    top["if"] = {"properties": {"kind": {"const": "tube"}}, "required": ["kind"]}
    top["then"] = {"required": ["tube"]}
    top["else"] = {"required": mat_tables}
    return top
