"""Design rules: small functions of the validated spec returning findings; none imports a CAD kernel.

The face: :class:`~matcad.rules.finding.Finding` (and its levels: ``error`` — `build` refuses without --force —,
``warning``, ``info``), :func:`check`, which runs every rule module of :mod:`matcad.rules.registry`, and
:func:`errors`. A rule module imports ``Finding`` from :mod:`matcad.rules.finding`, never from this face.
"""

from __future__ import annotations

from dataclasses import replace

from matcad.rules.finding import LEVELS, Finding, findings_text, verdict_dict
from matcad.rules.registry import PREDICTION_MODULES, SPEC_MODULES, TUBE_MODULES, TUBE_SPEC_RULES

__all__ = ["Finding", "check", "errors", "findings_text", "verdict_dict"]


def check(spec, prediction=None) -> list[Finding]:
    """Run every rule on ``spec``; ``prediction`` (:func:`matcad.prediction.predict` of a single-taxel spec) is computed when
    not given; a board's acoustic rules run on each taxel's own prediction. A board's one-taxel geometry rules run on
    each taxel; a finding that several taxels share word for word is listed once, naming them ("t1, t2: ...")."""
    if spec.kind == "tube":
        return _tube(spec, prediction)
    from matcad.prediction import predict
    from matcad.spec import taxel_spec, taxels

    board = taxels(spec)
    findings: list[Finding] = []
    per_taxel = ([rule for module in SPEC_MODULES for rule in getattr(module, "TAXEL_RULES", ())]
                 if len(board) > 1 else [])
    for module in SPEC_MODULES:
        for rule in module.RULES:
            if rule not in per_taxel:
                findings += rule(spec)
    shared: dict = {}  # a board's one-taxel geometry rules, on each taxel's own geometry
    for taxel in board if per_taxel else ():
        one = taxel_spec(spec, taxel)
        for rule in per_taxel:
            for f in rule(one):
                shared.setdefault(repr(f), (f, []))[1].append(taxel.name)
    findings += [replace(f, message=f"{', '.join(names)}: {f.message}") for f, names in shared.values()]
    for taxel in board:  # the sound rules per taxel, on its own prediction; a board's messages name the taxel
        one = taxel_spec(spec, taxel)
        p = (prediction or predict(one)) if len(board) == 1 else predict(one)
        for module in PREDICTION_MODULES:
            for rule in module.RULES:
                findings += [f if len(board) == 1 else replace(f, message=f"{taxel.name}: {f.message}")
                             for f in rule(one, p)]
    order = {level: i for i, level in enumerate(LEVELS)}
    return sorted(findings, key=lambda f: order[f.level])


def _tube(spec, prediction=None) -> list[Finding]:
    """A fipple tube's rules (:mod:`matcad.rules.tube`) and its cap's (the MAT cap and mold rules)."""
    from matcad.prediction.tube import predict_tube

    p = prediction or predict_tube(spec)
    findings = [f for rule in TUBE_SPEC_RULES for f in rule(spec)]
    findings += [f for module in TUBE_MODULES for rule in module.RULES for f in rule(spec, p)]
    order = {level: i for i, level in enumerate(LEVELS)}
    return sorted(findings, key=lambda f: order[f.level])


def errors(findings: list[Finding]) -> list[Finding]:
    """The findings at level ``error``."""
    return [f for f in findings if f.level == "error"]
