"""Design rules: small functions of the validated spec returning findings; none imports a CAD kernel.

Levels: ``error`` (the part will not work or cannot be made: `build` refuses without --force), ``warning``
(likely trouble; fix or accept knowingly), ``info`` (numbers worth knowing before casting).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

LEVELS = ("error", "warning", "info")


@dataclass(frozen=True)
class Finding:
    """One rule's verdict: id, level, the measured value, the limit it was held to, message and fix."""

    id: str
    level: str
    value: object
    limit: object
    message: str
    fix: str = ""

    def to_dict(self) -> dict:
        return asdict(self)


def check(spec, prediction=None) -> list[Finding]:
    """Run every rule on ``spec``; ``prediction`` (from acoustics.predict, of a single-taxel spec) is computed when
    not given; a board's acoustic rules run on each taxel's own prediction."""
    from matcad.prediction import predict
    from matcad.rules import acoustic, bands, board as board_rules, laser, printing, stack

    from matcad.spec import taxel_spec, taxels

    board = taxels(spec)
    findings: list[Finding] = []
    per_taxel = [rule for module in (printing, stack) for rule in module.TAXEL_RULES] if len(board) > 1 else []
    for module in (laser, printing, stack, bands, board_rules):
        for rule in module.RULES:
            if rule not in per_taxel:
                findings += rule(spec)
    for taxel in board if per_taxel else ():  # a board's one-taxel geometry rules, on each taxel's own geometry
        one = taxel_spec(spec, taxel)
        for rule in per_taxel:
            findings += [replace(f, message=f"{taxel.name}: {f.message}") for f in rule(one)]
    for taxel in board:  # the sound rules per taxel, on its own prediction; a board's messages name the taxel
        one = taxel_spec(spec, taxel)
        p = (prediction or predict(one)) if len(board) == 1 else predict(one)
        for rule in acoustic.RULES:
            findings += [f if len(board) == 1 else replace(f, message=f"{taxel.name}: {f.message}")
                         for f in rule(one, p)]
    order = {level: i for i, level in enumerate(LEVELS)}
    return sorted(findings, key=lambda f: order[f.level])


def errors(findings: list[Finding]) -> list[Finding]:
    return [f for f in findings if f.level == "error"]
