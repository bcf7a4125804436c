"""A validated spec back to TOML that :func:`matcad.spec.load` reads to the same spec (every default resolved, so
the file says exactly what was designed)."""

from __future__ import annotations


def plain(value):
    """Spec data as TOML-ready values: unset (None) fields dropped, tuples as lists."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items() if v is not None and v != [] and v != ()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def spec_toml(spec, header: str = "") -> str:
    """``spec`` (resolved) as TOML text, after ``header`` comment lines (each line prefixed '# ')."""
    import tomli_w

    from matcad.spec import to_dict

    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + tomli_w.dumps(plain(to_dict(spec)))


def write_design(target, spec, report: dict, header: str, picture=None) -> list[str]:
    """``<name>.toml`` (the designed spec), ``design.json`` (``report``) and, with ``picture`` (a function of the
    folder returning the file it drew), a PNG into the folder ``target``, through
    :func:`matcad.output.staged_output`: the folder appears complete or not at all. Returns the files' names."""
    import json

    from matcad.output import staged_output

    with staged_output(target) as tmp:
        (tmp / f"{spec.name}.toml").write_text(spec_toml(spec, header), encoding="utf-8")
        (tmp / "design.json").write_text(json.dumps(report, indent=2, allow_nan=False) + "\n", encoding="utf-8")
        drawn = [picture(tmp)] if picture is not None else []
    return [f"{spec.name}.toml", "design.json", *drawn]
