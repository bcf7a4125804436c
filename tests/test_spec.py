import math

import pytest

from matcad import spec as spec_mod
from matcad.spec import SpecError
from tests.conftest import MINIMAL, PAPER, TEMPLATES


def test_paper_template_values():
    s = spec_mod.load(PAPER)
    assert (s.cavity.diameter, s.cavity.length) == (3.18, 4.76)
    assert (s.neck.diameter, s.neck.length, s.neck.mouth) == (2.10, 6.35, "mount")
    assert s.spacer.height == 1.59
    assert s.calibration.area_convention == "d2/4"


@pytest.mark.parametrize("path", TEMPLATES, ids=lambda p: p.stem)
def test_every_template_validates(path):
    assert spec_mod.load(path).name


def test_defaults_fill_in():
    s = spec_mod.from_dict({"name": "x", "cavity": {"diameter": 3, "length": 4},
                            "neck": {"diameter": 2, "length": 6}})
    assert s.air.temperature_c == 20.0 and s.air.speed_of_sound is None
    assert s.wall.model == "rigid" and s.calibration is None
    assert isinstance(s.cavity.diameter, float)


def _with(section, key, value):
    data = {"name": "x", "cavity": {"diameter": 3.0, "length": 4.0}, "neck": {"diameter": 2.0, "length": 6.0}}
    data.setdefault(section, {})[key] = value
    return data


@pytest.mark.parametrize("section,key,value", [
    ("cavity", "diameter", 0), ("cavity", "diameter", -1.0), ("cavity", "length", math.nan),
    ("cavity", "length", math.inf), ("neck", "length", "6.35"), ("neck", "diameter", True),
    ("neck", "mouth", "flanged"), ("air", "temperature_c", -300.0), ("air", "speed_of_sound", 0.0),
    ("wall", "shear_modulus_mpa", [0.6, 0.2]), ("wall", "shear_modulus_mpa", 0.3),
    ("wall", "shear_modulus_mpa", [0.0, 0.3]), ("cavity", "diameter", 1e9),
])
def test_unphysical_values_name_field_and_range(section, key, value):
    with pytest.raises(SpecError) as err:
        spec_mod.from_dict(_with(section, key, value))
    assert err.value.field == f"{section}.{key}"
    assert f"{section}.{key}" in str(err.value) and "must be" in str(err.value)


def test_neck_wider_than_cavity_rejected_equal_accepted():
    with pytest.raises(SpecError, match="neck.diameter"):
        spec_mod.from_dict(_with("neck", "diameter", 3.5))
    assert spec_mod.from_dict(_with("neck", "diameter", 3.0)).neck.diameter == 3.0


def test_unknown_key_did_you_mean():
    with pytest.raises(SpecError) as err:
        spec_mod.from_dict(_with("cavity", "lenght", 4.0))
    assert err.value.field == "cavity.lenght" and "did you mean 'length'" in str(err.value)
    with pytest.raises(SpecError, match="did you mean 'cavity'"):
        spec_mod.from_dict({**_with("cavity", "length", 4.0), "cavty": {}})


@pytest.mark.parametrize("name", ["../evil", "a/b", "", ".", "x" * 65, "é", 5])
def test_names_that_are_not_folder_names_rejected(name):
    data = _with("cavity", "length", 4.0)
    data["name"] = name
    with pytest.raises(SpecError, match="^name"):
        spec_mod.from_dict(data)


def test_missing_required(write_spec):
    with pytest.raises(SpecError, match=r"^neck\.length"):
        spec_mod.load(write_spec(MINIMAL.replace("length = 6.35\n", "")))
    with pytest.raises(SpecError, match="spec file"):
        spec_mod.load(write_spec("name = [unclosed"))


def test_any_physical_scale_accepted():
    for scale in (0.01, 1.0, 30.0):
        data = {"name": "x", "cavity": {"diameter": 3.18 * scale, "length": 4.76 * scale},
                "neck": {"diameter": 2.1 * scale, "length": 6.35 * scale}}
        assert spec_mod.from_dict(data).cavity.diameter == pytest.approx(3.18 * scale)


def test_schema_covers_every_field():
    rows = spec_mod.schema()
    keys = {r["key"] for r in rows}
    assert {"cavity.diameter", "neck.mouth", "air.speed_of_sound", "wall.shear_modulus_mpa",
            "calibration.area_convention"} <= keys
    assert all(r["doc"] and r["allowed"] for r in rows)
    assert next(r for r in rows if r["key"] == "cavity.diameter")["unit"] == "mm"
