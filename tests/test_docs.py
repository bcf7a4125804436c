"""docs/api.md runs: its Python cells, executed in order in one namespace from an empty folder (not the
repository: a user's notebook sits anywhere)."""

import os
import re
import shutil

from tests.conftest import ROOT


def test_api_page_cells_run(tmp_path):
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    cells = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(cells) >= 4
    namespace: dict = {}
    cwd = os.getcwd()
    os.chdir(tmp_path)  # nothing relative to the repository may be needed
    try:
        for cell in cells:
            exec(compile(cell, "docs/api.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    sweep = namespace["sweep"]
    assert (sweep[1:, 1] < sweep[:-1, 1]).all()  # a longer cavity sings lower
    out = namespace["out"]
    try:
        assert (out / "report.html").is_file() and (out / "sweep.png").stat().st_size > 1000
    finally:
        shutil.rmtree(out.parent, ignore_errors=True)
