"""Build matcad/export/dxf_template.txt: ezdxf's R2010 document with matcad's four layers and no entity, its
handle-dependent values marked, into which :func:`matcad.export.dxf_svg.write_dxf` writes the entities, so that a
build writes ezdxf's bytes without importing ezdxf.

    python benchmarks/dxf_template.py      # after an ezdxf upgrade (tests/test_fast_pictures.py says when)
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from matcad.export.dxf_svg import TEMPLATE, dxf_template
from matcad.parts.catalogue import laser_parts
from matcad.parts.flat import cut_plan
from matcad.spec import load

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    spec = load(ROOT / "templates" / "mat-laser-only.toml")
    plan = next(p for p in (cut_plan(f, True) for f in laser_parts(spec)) if p.circles)
    with tempfile.TemporaryDirectory() as tmp:
        TEMPLATE.write_text(dxf_template(plan, Path(tmp)), encoding="utf-8", newline="\n")
    print(TEMPLATE)


if __name__ == "__main__":
    main()
