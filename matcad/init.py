"""`matcad init NAME [--from TEMPLATE]`: a new spec file from a shipped template, renamed, never overwriting."""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

DEFAULT_TEMPLATE = "mat-paper"
_NAME_LINE = re.compile(r'^name\s*=\s*"[^"\n]*"', flags=re.M)


def template_names() -> list[str]:
    """Names of the templates shipped in the package (``matcad/templates/*.toml``)."""
    folder = resources.files("matcad") / "templates"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def template_path(name: str) -> Path:
    """A shipped template's file by name; ValueError listing the names for any other."""
    names = template_names()
    if name not in names:
        raise ValueError(f"template {name!r} invalid, must be one of {', '.join(names)}")
    return Path(str(resources.files("matcad") / "templates" / f"{name}.toml"))


def new_spec(name: str, template: str = DEFAULT_TEMPLATE, path: Path | None = None) -> Path:
    """Write ``path`` (default ``NAME.toml``) from ``template`` with its ``name`` set to ``name``; the template's
    comments (each number's source) are kept. Raises SpecError for a bad name, ValueError for an unknown
    template, FileExistsError rather than overwrite."""
    from matcad.spec import from_dict, read_spec_data

    source = template_path(template)
    text = source.read_text(encoding="utf-8")
    renamed, count = _NAME_LINE.subn(f'name = "{name}"', text, count=1)
    if count != 1:
        raise ValueError(f"template {template!r} has no name line to set")
    target = Path(path) if path is not None else Path(f"{name}.toml")
    from_dict(read_spec_data(source) | {"name": name})  # the name must be valid before anything is written
    with open(target, "x", encoding="utf-8") as f:  # "x": never replace an existing file
        f.write(renamed)
    return target
