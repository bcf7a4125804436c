"""The design-rule modules :func:`matcad.rules.check` runs, in the order their findings are listed within a level.

Adding a rule is one function in a module's ``RULES`` tuple; adding a rule module is that module and one entry
here (docs/extending.md). A module of :data:`SPEC_MODULES` may also name, in ``TAXEL_RULES``, those of its
``RULES`` that read one taxel's own geometry: a board runs them on each taxel instead of on the whole spec; and in
``INFO_RULES`` those that only inform (never an error or a warning), which a sweep's verdict columns skip; and in
``ARRAY_RULES`` those a sweep judges on arrays of variants, each with the function of the spec it memoises for it.
"""

from __future__ import annotations

from matcad.rules import acoustic, bands, board, jet, laser, plate, printing, stack, tube

SPEC_MODULES = (laser, printing, stack, bands, board, plate)
"""Modules whose ``RULES`` are functions of the spec: ``rule(spec) -> list[Finding]``."""
PREDICTION_MODULES = (acoustic, jet)
"""Modules whose ``RULES`` judge one taxel's predicted sound: ``rule(taxel_spec, prediction) -> list[Finding]``,
run on every taxel with its own prediction."""
TUBE_MODULES = (tube,)
"""Modules whose ``RULES`` judge a ``kind = "tube"`` spec: ``rule(spec, tube_prediction) -> list[Finding]``."""
TUBE_SPEC_RULES = (printing.printable_walls, printing.key_clearance, printing.fill_and_vents, printing.cap_wall,
                   printing.silicone_batch, printing.sla_inhibition)
"""The MAT rules a tube spec also runs: its cap and the cap's mold are the MAT path's."""
