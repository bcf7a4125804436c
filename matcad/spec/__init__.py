"""Geometry spec: TOML → validated, frozen dataclasses. All lengths in millimetres.

Each field is declared once, with its unit, default, allowed range and meaning; the same declaration
validates input, prints ``matcad schema`` and documents the template. Validation rejects only what is not
physical (non-positive or non-finite lengths, wrong types, a neck wider than its cavity); what is merely hard
to fabricate is a design rule, not an input error.

Dimension names follow the paper (mat-paper.md, Fig. 2): D, L the silicone cavity; d, l the acrylic neck.

This module is the face of the package; each name lives in one module of it:

- :mod:`~matcad.spec.fields` — a field's declaration and converter, :class:`SpecError`, the :class:`Section` base;
- :mod:`~matcad.spec.sections`, :mod:`~matcad.spec.calibration` — one dataclass per TOML table;
- :mod:`~matcad.spec.board` — the board of taxels as typed :class:`Taxel` values;
- :mod:`~matcad.spec.cap` — the cast cap's derived dimensions (flange, height);
- :mod:`~matcad.spec.checks` — the cross-field checks of a whole spec;
- :mod:`~matcad.spec.derive` — the reference taxel's spec and model variants;
- :mod:`~matcad.spec.model` — :class:`Spec`, parsed TOML to a resolved Spec and back;
- :mod:`~matcad.spec.io` — reading spec, report.json and calibration files, ``--set``;
- :mod:`~matcad.spec.schema` — ``matcad schema``;
- :mod:`~matcad.spec.notes` — likely unit slips in a valid spec.
"""

from matcad.spec.board import Taxel, field_path, is_array, taxel_spec, taxels
from matcad.spec.calibration import Calibration
from matcad.spec.cap import (cap_flange_diameter_mm, cap_flange_thickness_mm, cap_height_mm, in_pocket,
                             neck_length_mm)
from matcad.spec.derive import calibrated_spec, reference_spec, variant
from matcad.spec.fields import Section, SpecError
from matcad.spec.io import apply_sets, load, load_calibration, load_spec, read_spec_data
from matcad.spec.model import SECTIONS, Spec, from_dict, to_dict
from matcad.spec.notes import frequency_notes, spec_notes
from matcad.spec.schema import schema, schema_text
from matcad.spec.sections import (MAX_TAXELS, Air, Array, Cavity, EndCap, Fasteners, Guide, Machine, Mechanics,
                                  Microphone, Mold, Mount, Neck, Needle, Outputs, Plate, Reference, Riser,
                                  Silicone, Spacer, TaxelEntry, Wall)

__all__ = [
    "MAX_TAXELS", "SECTIONS", "Air", "Array", "Calibration", "Cavity", "EndCap", "Fasteners", "Guide", "Machine",
    "Mechanics", "Microphone", "Mold", "Mount", "Neck", "Needle", "Outputs", "Plate", "Reference", "Riser", "Section",
    "Silicone", "Spacer", "Spec", "SpecError", "Taxel", "TaxelEntry", "Wall", "apply_sets", "calibrated_spec",
    "cap_flange_diameter_mm", "cap_flange_thickness_mm", "cap_height_mm", "field_path", "frequency_notes",
    "from_dict", "in_pocket", "is_array", "load", "load_calibration", "load_spec", "neck_length_mm", "read_spec_data",
    "reference_spec", "schema", "schema_text", "spec_notes", "taxel_spec", "taxels", "to_dict", "variant"]
