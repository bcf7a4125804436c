"""Design rules: small functions of the validated spec returning findings; none imports a CAD kernel.

Levels: ``error`` (the part will not work or cannot be made: `build` refuses without --force), ``warning``
(likely trouble; fix or accept knowingly), ``info`` (numbers worth knowing before casting).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

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
    """Run every rule on ``spec``; ``prediction`` (from acoustics.predict) is computed when not given."""
    from matcad.acoustics.predict import predict
    from matcad.rules import acoustic, bands, laser, printing, stack

    prediction = prediction or predict(spec)
    findings: list[Finding] = []
    for module in (laser, printing, stack, bands):
        for rule in module.RULES:
            findings += rule(spec)
    for rule in acoustic.RULES:
        findings += rule(spec, prediction)
    order = {level: i for i, level in enumerate(LEVELS)}
    return sorted(findings, key=lambda f: order[f.level])


def errors(findings: list[Finding]) -> list[Finding]:
    return [f for f in findings if f.level == "error"]
