"""`matcad schema --json` is a real JSON Schema (draft 2020-12) that editors can use on a TOML spec: it is a valid
schema, every shipped template satisfies it, what it refuses the loader refuses too, and the copy shipped in the
package is the command's output."""

from __future__ import annotations

import json
import tomllib

import pytest
from jsonschema import Draft202012Validator

from matcad.spec import SpecError, from_dict
from tests.conftest import ROOT, run_cli

TEMPLATES = sorted((ROOT / "matcad" / "templates").glob("*.toml"))


@pytest.fixture(scope="module")
def validator():
    code, out, err = run_cli("schema", "--json")
    assert code == 0, err
    schema = json.loads(out)
    Draft202012Validator.check_schema(schema)  # a schema of the 2020-12 dialect, not just JSON
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    return Draft202012Validator(schema)


@pytest.mark.parametrize("template", TEMPLATES, ids=lambda p: p.stem)
def test_templates_satisfy_the_schema(validator, template):
    errors = [f"{list(e.path)}: {e.message}" for e in validator.iter_errors(tomllib.loads(template.read_text()))]
    assert errors == []


MUTATIONS = [
    ("cavity", "diameter", -1.0),          # below its bound
    ("neck", "mouth", "flanged"),          # not a choice
    ("neck", "diamter", 2.0),              # unknown key (a typo)
    ("cavity", "length", "5 mm"),          # text for a number
    ("machine", "printer", "resin"),
    ("wall", "loss_factor", [0.1]),        # a range needs two numbers
]


@pytest.mark.parametrize("table,key,value", MUTATIONS)
def test_what_the_schema_refuses_the_loader_refuses(validator, table, key, value):
    data = tomllib.loads((ROOT / "matcad" / "templates" / "mat-paper.toml").read_text())
    data.setdefault(table, {})[key] = value
    assert list(validator.iter_errors(data)), f"{table}.{key} = {value!r} passed the schema"
    with pytest.raises(SpecError):
        from_dict(data)


def test_missing_required_table_is_refused(validator):
    data = tomllib.loads((ROOT / "matcad" / "templates" / "mat-paper.toml").read_text())
    del data["neck"]
    assert any("neck" in e.message for e in validator.iter_errors(data))


def test_each_kind_requires_its_own_tables(validator):
    """kind = "tube" needs [tube] and not the MAT taxel's [cavity]/[neck]; the loader agrees on the refusal."""
    tube = tomllib.loads((ROOT / "matcad" / "templates" / "acoustac-tube.toml").read_text())
    assert "cavity" not in tube and list(validator.iter_errors(tube)) == []
    del tube["tube"]
    assert any("'tube' is a required property" in e.message for e in validator.iter_errors(tube))
    with pytest.raises(SpecError):
        from_dict(tube)


def test_descriptions_carry_units_and_defaults(validator):
    props = validator.schema["properties"]
    assert "[mm]" in props["cavity"]["properties"]["diameter"]["description"]
    assert props["neck"]["properties"]["mouth"]["enum"] == ["baffled", "unflanged", "mount"]
    item = props["taxel"]["items"]["properties"]
    assert item["calibration"]["properties"]["covariance"]["minItems"] == 9


def test_shipped_schema_is_the_commands_output(validator):
    shipped = json.loads((ROOT / "matcad" / "templates" / "matcad.schema.json").read_text())
    assert shipped == validator.schema, "regenerate: matcad schema --json > matcad/templates/matcad.schema.json"


def test_rows_stay_available():
    code, out, _ = run_cli("schema", "--json", "--rows")
    rows = json.loads(out)
    assert code == 0 and any(r["key"] == "neck.mouth" and "mount" in r["allowed"] for r in rows)
