"""Shared test helpers: paths, a spec writer, and a CLI runner in a fresh interpreter."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("matcad", derandomize=True, deadline=None, print_blob=True)
settings.load_profile("matcad")
"""Property tests draw the same examples on every run, so `main` stays green or red for a reason in the code, not
in the draw; benchmarks/fuzz.py explores at random (>= 10 000 specs) and turns what it finds into examples here."""

ROOT = Path(__file__).resolve().parents[1]
TUBE_TEMPLATES = [p for p in sorted((ROOT / "templates").glob("*.toml")) if 'kind = "tube"' in p.read_text(encoding="utf-8")]
"""Fipple-tube templates (docs/tube.md): tested in tests/test_tube_*.py; the MAT kit's tests run on the others."""
TEMPLATES = [p for p in sorted((ROOT / "templates").glob("*.toml")) if p not in TUBE_TEMPLATES]
PAPER = ROOT / "templates" / "mat-paper.toml"
BOARD_TEMPLATES = [p for p in TEMPLATES if "[[taxel]]" in p.read_text(encoding="utf-8") or "[array]" in p.read_text(
    encoding="utf-8")]
SINGLE_TEMPLATES = [p for p in TEMPLATES if p not in BOARD_TEMPLATES]
"""Templates of one taxel at the plate centre: the tests that measure that taxel's parts in place run on these;
a board's parts are measured in tests/test_board.py."""

MINIMAL = """name = "t"
[cavity]
diameter = 3.18
length = 4.76
[neck]
diameter = 2.1
length = 6.35
"""
FAST_MECHANICS = MINIMAL + """[end_cap]
outer_diameter = 8.0
top_thickness = 2.0
[mechanics]
material = "neo_hookean"
shear_modulus_mpa = 0.3
displacement_mm = 1.0
steps = 4
"""
"""MINIMAL with a cheap cap-mechanics run (coarse neo-Hookean, 4 steps to 1 mm): seconds, not tens."""


REQUIRE_CLIENTS = os.environ.get("MATCAD_REQUIRE_CLIENTS") == "1"
"""Set by .ci/run, which installs every client a test drives (a browser, bash, Debian's readers)."""


def missing_client(why: str, here: str, ci: str) -> None:
    """A client a test needs is missing: fail under :data:`REQUIRE_CLIENTS` (``ci`` says what CI should have
    done), else skip (``here`` says how to install it to run the test here)."""
    if REQUIRE_CLIENTS:
        pytest.fail(f"{why} but MATCAD_REQUIRE_CLIENTS=1 ({ci})")
    pytest.skip(f"{why}: {here}")


def spec_with(path, **over):
    """The spec in TOML file ``path`` with fields replaced: ``section__field=value`` (validated, a Spec)."""
    import tomllib

    from matcad import spec as spec_mod

    data = tomllib.loads(Path(path).read_text())
    for key, value in over.items():
        section, field = key.split("__")
        data.setdefault(section, {})[field] = value
    return spec_mod.from_dict(data)


def run_cli(*args, cwd=None):
    """Run `python -m matcad ARGS` in a fresh process: (exit code, stdout, stderr)."""
    proc = subprocess.run([sys.executable, "-m", "matcad", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd or ROOT)
    return proc.returncode, proc.stdout, proc.stderr


@pytest.fixture
def write_spec(tmp_path):
    """Write TOML text to a file and return its path."""
    def _write(text, name="spec.toml"):
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path
    return _write
