"""A statistical target as the plan writes it (docs/statistics.md):
``violation probability <= 1e-3 at 95 % per run``.  Below the plan's
values (:mod:`.model`) and its checks (:mod:`.targets`), which both use it;
the numbers are decided by :mod:`rclverify.records.statistics`.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from rclverify.records.statistics import TargetJson

#: What a target counts: a whole run with any violation, or one judged answer.
PER = ("run", "answer")


@dataclass(frozen=True)
class Target:
    """A plan's target: the violation probability ``bound`` (0 < bound < 1)
    at confidence ``level`` (0.5 <= level < 1), counted ``per`` run or per
    judged answer; ``text`` as written (blanks folded); ``guarantee`` the
    1-based guarantee it is about (``of guarantee 2``), 0 for the whole
    contract."""

    bound: float
    level: float
    per: str
    text: str
    guarantee: int = 0

    def to_json(self) -> TargetJson:
        return {"bound": self.bound, "level": self.level, "per": self.per, "text": self.text,
                "guarantee": self.guarantee}

    def words(self) -> str:
        """``violation probability <= 0.001 at 95 % per run`` (normalised)."""
        of = f" of guarantee {self.guarantee}" if self.guarantee else ""
        return f"violation probability <= {self.bound:g} at {self.level * 100:g} % per {self.per}{of}"


_NUMBER = r"(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_TARGET = re.compile(rf"^\s*violation\s+probability\s*<=\s*({_NUMBER})\s*(%?)\s+at\s+({_NUMBER})\s*(%?)"
                     rf"(?:\s+per\s+(\w+))?(?:\s+of\s+guarantee\s+(\d+))?\s*$")


def parse_target(text: str) -> Target:
    """``violation probability <= 1e-3 at 95 % per run`` (``per answer``;
    ``per run`` when left out; the bound and the level as a fraction or a
    percentage with ``%``), optionally ``of guarantee K`` (K >= 1).  Raises
    ``ValueError`` with the reason."""
    m = _TARGET.match(text) if isinstance(text, str) else None
    if m is None:
        raise ValueError(f"a target reads 'violation probability <= 1e-3 at 95 % per run' (or per answer; "
                         f"'of guarantee K' for one guarantee), not {text!r}")
    bound = float(m.group(1)) / (100.0 if m.group(2) else 1.0)
    level = float(m.group(3)) / (100.0 if m.group(4) else 1.0)
    per = m.group(5) or "run"
    if per not in PER:
        raise ValueError(f"a target counts per run or per answer, not per {per!r}")
    if not 0.0 < bound < 1.0:
        raise ValueError(f"a target's violation probability is between 0 and 1 (exclusive), not {m.group(1)}{m.group(2)}")
    if not 0.5 <= level < 1.0:
        raise ValueError(f"a target's confidence level is at least 50 % and below 100 %, not {m.group(3)}{m.group(4)}")
    guarantee = int(m.group(6) or 0)
    if m.group(6) is not None and guarantee < 1:
        raise ValueError("a target's guarantee is a 1-based index, not 0")
    return Target(bound, level, per, " ".join(text.split()), guarantee)


__all__ = ["PER", "Target", "parse_target"]
