"""The house keeps its floors: docs/architecture.md's floor table against the package's own imports.

Every import of a matcad module counts, at module level or inside a function. A module may import modules of its
own floor and of lower ones; no two modules import each other in a loop; no module imports another module's
private (``_name``) definition; every module of the package is on exactly one floor; no module grows past the size
of one job.
"""

import ast
import re
from pathlib import Path

from tests.conftest import ROOT

PACKAGE = ROOT / "matcad"
MAX_LINES = 450


def _floors() -> dict[str, int]:
    """docs/architecture.md's floor table: module or package path (as written, e.g. `matcad/spec/`) → floor."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = text.split("## Floors", 1)[1].split("\n## ", 1)[0]
    floors = {}
    for row in table.splitlines():
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        match = re.match(r"(\d+) ", cells[0]) if len(cells) > 2 else None
        if match:
            for path in re.findall(r"`(matcad/[^`]*)`", cells[1]):
                floors[path] = int(match.group(1))
    return floors


def _module_name(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _floor_of(module: str, floors: dict[str, int]) -> int:
    path = module.replace(".", "/")
    candidates = [(len(key), floor) for key, floor in floors.items()
                  if key.removesuffix(".py") == path or (key.endswith("/") and (path + "/").startswith(key))
                  or (key.endswith("__init__.py") and key.removesuffix("/__init__.py") == path)]
    assert candidates, f"{module} is on no floor of docs/architecture.md"
    return max(candidates)[1]


def _imports(module: str, path: Path):
    """(imported matcad module, names taken from it, line) for every import in ``path``, at any depth."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("matcad"):
                    yield _resolve(alias.name), [], node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                root = ".".join(base + ([node.module] if node.module else []))
            else:
                root = node.module or ""
            if not root.startswith("matcad"):
                continue
            for alias in node.names:  # a submodule imported by name is an import of that module
                sub = f"{root}.{alias.name}"
                if sub in MODULES:
                    yield sub, [], node.lineno
                else:
                    yield _resolve(root), [alias.name], node.lineno


def _resolve(name: str) -> str:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name


EDGES = [(m, target, names, line) for m, p in MODULES.items() for target, names, line in _imports(m, p)
         if target and target != m]


def test_every_module_is_on_one_floor_and_imports_run_down():
    floors = _floors()
    assert len(floors) >= 14
    up = [f"{m}:{line} (floor {_floor_of(m, floors)}) imports {t} (floor {_floor_of(t, floors)})"
          for m, t, _, line in EDGES if _floor_of(t, floors) > _floor_of(m, floors)]
    assert not up, "imports that run up the floors:\n" + "\n".join(up)


def test_no_import_cycle():
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for m, t, _, _ in EDGES:
        if not m.startswith(t + "."):  # a module importing its own package's face is not a loop
            graph[m].add(t)
    index, low, stack, on_stack, cycles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


def test_no_module_imports_a_private_name_of_another():
    private = [f"{m}:{line} takes {name} from {t}" for m, t, names, line in EDGES for name in names
               if name.startswith("_") and not name.startswith("__")]
    assert not private, "\n".join(private)


def test_modules_keep_to_one_job_in_size():
    big = {m: n for m, p in MODULES.items() if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not big, f"modules over {MAX_LINES} lines: {big}"
    assert len((PACKAGE / "cli.py").read_text(encoding="utf-8").splitlines()) < 350
