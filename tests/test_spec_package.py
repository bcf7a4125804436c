"""The spec floor stays the floor: matcad/spec imports nothing of matcad above the base floor (docs/architecture.md)."""

import ast
import sys

from tests.conftest import ROOT

SPEC = ROOT / "matcad" / "spec"
BASE = {"matcad.errors", "matcad.inputs", "matcad.materials", "matcad.listening"}
"""The base modules the spec floor may import besides its own package (listening: the kHz-slip threshold lives with
the listening band, so that `analyze --band` checks it without loading the spec; issue 25)."""
LAZY = {"numpy"}
"""Not the standard library, but allowed inside a function: the calibration's covariance check needs eigenvalues."""


def _imports(path):
    """(module imported, whether inside a function) for every import statement of ``path``, relative ones resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    in_function = {id(node) for fn in ast.walk(tree) if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef))
                   for node in ast.walk(fn) if node is not fn}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from ((alias.name, id(node) in in_function) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = ".".join(["matcad", "spec"][:3 - node.level]) if node.level else ""
            module = ".".join(part for part in (base, node.module) if part)
            if module == "matcad":
                yield from ((f"matcad.{alias.name}", id(node) in in_function) for alias in node.names)
            else:
                yield module, id(node) in in_function


def test_spec_modules_import_only_the_spec_package_the_base_floor_and_the_standard_library():
    files = sorted(SPEC.glob("*.py"))
    assert len(files) > 1
    bad = []
    for path in files:
        for module, lazy in _imports(path):
            top = module.split(".")[0]
            if module == "matcad.spec" or module.startswith("matcad.spec.") or module in BASE:
                continue
            if top != "matcad" and (top in sys.stdlib_module_names or (lazy and top in LAZY)):
                continue
            bad.append(f"{path.name}: {module}")
    assert not bad, bad
