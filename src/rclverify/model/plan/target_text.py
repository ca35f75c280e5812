"""A statistical target as the plan writes it (docs/statistics.md):
``violation probability <= 1e-3 at 95 % per run``, or a margin target
``margin of guarantee 1 >= 0.1 in 99 % of answers at 95 %`` (the
guarantee's space margin, docs/semantics.md "Margins", at least 0.1 on 99 %
of answers, bounded at 95 % confidence: a trial whose margin is below 0.1
counts as a violation of a ``violation probability <= 1 %`` target).  Below the plan's
values (:mod:`.model`) and its checks (:mod:`.targets`), which both use it;
the numbers are decided by :mod:`rclverify.records.statistics`.
"""
from __future__ import annotations

import re
from fractions import Fraction
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
    contract; ``margin`` the least space margin a trial must keep (a margin
    target; ``None``: a violation target), in the unit of the comparison
    that decides the guarantee's margin."""

    bound: float
    level: float
    per: str
    text: str
    guarantee: int = 0
    margin: float | None = None

    def to_json(self) -> TargetJson:
        out: TargetJson = {"bound": self.bound, "level": self.level, "per": self.per, "text": self.text,
                           "guarantee": self.guarantee}
        if self.margin is not None:
            out["margin"] = self.margin
        return out

    def words(self) -> str:
        """``violation probability <= 0.001 at 95 % per run`` or ``margin of
        guarantee 1 >= 0.1 in 99 % of answers at 95 %`` (normalised)."""
        if self.margin is not None:
            return (f"margin of guarantee {self.guarantee} >= {self.margin:g} in {(1 - self.bound) * 100:g} % "
                    f"of {self.per}s at {self.level * 100:g} %")
        of = f" of guarantee {self.guarantee}" if self.guarantee else ""
        return f"violation probability <= {self.bound:g} at {self.level * 100:g} % per {self.per}{of}"


_NUMBER = r"(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_TARGET = re.compile(rf"^\s*violation\s+probability\s*<=\s*({_NUMBER})\s*(%?)\s+at\s+({_NUMBER})\s*(%?)"
                     rf"(?:\s+per\s+(\w+))?(?:\s+of\s+guarantee\s+(\d+))?\s*$")


_MARGIN = re.compile(rf"^\s*margin\s+of\s+guarantee\s+(\d+)\s*>=\s*(-?{_NUMBER})\s+in\s+({_NUMBER})\s*(%?)"
                     rf"\s+of\s+(\w+?)s?\s+at\s+({_NUMBER})\s*(%?)\s*$")


def _margin_target(m: re.Match[str], text: str) -> Target:
    """A margin target (module docstring) from its match ``m``."""
    guarantee, margin = int(m.group(1)), float(m.group(2))
    share = Fraction(m.group(3)) / (100 if m.group(4) else 1)  # exact: 99 % leaves 0.01, not 0.010000000000000009
    per, level = m.group(5), float(m.group(6)) / (100.0 if m.group(7) else 1.0)
    if guarantee < 1:
        raise ValueError("a margin target's guarantee is a 1-based index, not 0")
    if per not in PER:
        raise ValueError(f"a margin target counts answers or runs, not {m.group(5)}s")
    if not 0.0 < share < 1.0:
        raise ValueError(f"a margin target's share of {per}s is between 0 and 100 % (exclusive), not "
                         f"{m.group(3)}{m.group(4)}")
    if not 0.5 <= level < 1.0:
        raise ValueError(f"a target's confidence level is at least 50 % and below 100 %, not {m.group(6)}{m.group(7)}")
    return Target(float(1 - share), level, per, " ".join(text.split()), guarantee, margin)


def parse_target(text: str) -> Target:
    """``violation probability <= 1e-3 at 95 % per run`` (``per answer``;
    ``per run`` when left out; the bound and the level as a fraction or a
    percentage with ``%``), optionally ``of guarantee K`` (K >= 1); or
    ``margin of guarantee K >= M in Q % of answers at L %`` (``of runs``: a
    run keeps the margin when its smallest does; the share ``Q`` and the
    level as a fraction or a percentage).  Raises ``ValueError`` with the
    reason."""
    mm = _MARGIN.match(text) if isinstance(text, str) else None
    if mm is not None:
        return _margin_target(mm, text)
    m = _TARGET.match(text) if isinstance(text, str) else None
    if m is None:
        raise ValueError(f"a target reads 'violation probability <= 1e-3 at 95 % per run' (or per answer; "
                         f"'of guarantee K' for one guarantee) or 'margin of guarantee K >= 0.1 in 99 % of "
                         f"answers at 95 %', not {text!r}")
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
