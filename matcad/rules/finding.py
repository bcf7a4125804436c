"""A design rule's verdict, and the levels it may have.

Levels: ``error`` (the part will not work or cannot be made: `build` refuses without --force), ``warning``
(likely trouble; fix or accept knowingly), ``info`` (numbers worth knowing before casting).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

LEVELS = ("error", "warning", "info")
"""Every finding's level, most severe first: findings are listed in this order."""


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
