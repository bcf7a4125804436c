"""The cap-curve disk cache (matcad.mechanics.store): a curve read back equals the one computed, a bad or foreign
file is recomputed, an empty MATCAD_CACHE_DIR turns it off, and a board's listening bands cost no FElupe run the
second time, in a fresh interpreter."""

import subprocess
import sys
import tomllib

import numpy as np
import pytest

from matcad import spec as spec_mod
from matcad.mechanics import solver, store
from matcad.mechanics.case import cap_case
from tests.conftest import FAST_MECHANICS, ROOT


@pytest.fixture
def case():
    return cap_case(spec_mod.from_dict(tomllib.loads(FAST_MECHANICS)))


def test_a_stored_curve_reads_back_equal(case, tmp_path, monkeypatch):
    monkeypatch.setenv("MATCAD_CACHE_DIR", str(tmp_path))
    computed = solver.cap_curve(case)
    monkeypatch.setattr(solver, "compress", lambda *a, **k: pytest.fail("the cached curve was recomputed"))
    again = solver.cap_curve(case)
    assert again.section == computed.section and again.material == computed.material
    assert len(again.steps) == len(computed.steps) > 0 and again.complete == computed.complete
    for a, b in zip(again.steps, computed.steps):
        assert (a.force_n, a.cavity_volume_mm3, a.volume_ratio_range) == (b.force_n, b.cavity_volume_mm3,
                                                                          b.volume_ratio_range)
        np.testing.assert_array_equal(a.cavity_outline, b.cavity_outline)
    np.testing.assert_array_equal(again.unloaded_outline, computed.unloaded_outline)


def test_bad_or_foreign_files_are_recomputed(case, tmp_path, monkeypatch):
    monkeypatch.setenv("MATCAD_CACHE_DIR", str(tmp_path))
    computed = solver.cap_curve(case)
    path = tmp_path / f"{store.key(case)[0]}.npz"
    path.write_bytes(b"not an npz archive")
    assert store.load(case, solver.CapCurve, solver.CapStep) is None
    other = cap_case(spec_mod.from_dict(tomllib.loads(FAST_MECHANICS.replace("steps = 4", "steps = 5"))))
    store.save(other, computed)
    path.write_bytes((tmp_path / f"{store.key(other)[0]}.npz").read_bytes())  # another case under this name
    assert store.load(case, solver.CapCurve, solver.CapStep) is None
    assert solver.cap_curve(case).steps[-1].force_n == computed.steps[-1].force_n  # recomputed, stored again
    assert store.load(case, solver.CapCurve, solver.CapStep) is not None


def test_empty_cache_dir_turns_it_off(case, tmp_path, monkeypatch):
    monkeypatch.setenv("MATCAD_CACHE_DIR", "")
    assert store.folder() is None and store.load(case, solver.CapCurve, solver.CapStep) is None
    store.save(case, None)  # nothing to write to: no error


BOARD = FAST_MECHANICS + "max_force_n = 6.0\n" + """
[[taxel]]
x = -6.0
y = 0.0
[[taxel]]
x = 6.0
y = 0.0
cavity_length = 4.0
"""


def test_listening_bands_of_a_board_cost_no_mechanics_the_second_time(tmp_path):
    path = tmp_path / "board.toml"
    path.write_text(BOARD)
    code = ("import sys; from matcad import spec; from matcad.prediction.bands import listening_bands; "
            "print(listening_bands(spec.load(sys.argv[1]))); print('felupe' in sys.modules)")
    env = {"MATCAD_CACHE_DIR": str(tmp_path / "cache"), "PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT)}
    runs = [subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, env=env,
                           cwd=ROOT) for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    (first, used_first), (second, used_second) = (r.stdout.splitlines() for r in runs)
    assert first == second and used_first == "True" and used_second == "False"
    assert len(list((tmp_path / "cache").glob("*.npz"))) == 2  # two distinct caps
