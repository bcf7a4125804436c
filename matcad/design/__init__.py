"""Inverse design: from a target frequency (or a band to share among N taxels) to a spec.

- :mod:`matcad.design.solve` — one taxel's f0 onto a target by varying chosen fields (stock sheet thickness
  first, then the continuous fields by root finding), within the design rules;
- :mod:`matcad.design.allocate` — N disjoint bands (guard and harmonic rule) in [LO, HI], one taxel solved for
  each, in two staggered columns clear of every needle's jet, as an array spec;
- :mod:`matcad.design.spec_toml` — a validated spec written back as TOML that `matcad check` reads.

Frequencies Hz, lengths mm. Errors: :class:`Unreachable` (a ValueError: the CLI's exit 2, bad input, naming the
fields, their ranges and what they reach) and :class:`RulesFailed` (exit 1, the rule findings).
"""


class Unreachable(ValueError):
    """The target cannot be met with the fields and ranges given (the message says what they reach)."""


class RulesFailed(Exception):
    """Every solution found breaks a design rule at level error; ``findings`` are the best solution's."""

    def __init__(self, message: str, findings):
        self.findings = findings
        super().__init__(message)
