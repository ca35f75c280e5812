"""Two-token corrections of one line (docs/diagnosis.md, "Two-token repairs"): two of the line's one-token
corrections made together, tried only when no one-token correction of the culprit line or of the lines
around it passes (a band written ``2 < x and x < 8`` where the contract says ``<=`` on both sides: each
strictness alone still fails at the other end).

:func:`pair_edits` takes the one-token corrections of the culprit line as :func:`.code_repair.candidate_edits`
ranks them, keeps the first :data:`PAIR_FROM` that lie on that one line, and joins each two that do not
overlap into one edit of the text between them (:func:`joined`), the pairs of better-ranked corrections
first (the sum of their two ranks, then the first's), at most :data:`MAX_PAIRS`.  Each is checked as a
one-token correction is (:func:`.code_repair_check.checked_repairs`).
"""
from __future__ import annotations

from typing import Sequence

from rclverify.diagnosis.edits import Edit

#: Most two-token corrections tried for one failure.
MAX_PAIRS = 12
#: The best-ranked one-token corrections of the line that pairs are made of.
PAIR_FROM = 8


def joined(source: str, a: Edit, b: Edit) -> Edit | None:
    """One edit making ``a`` and ``b`` (edits of one line of ``source``, ``a`` ending before ``b`` starts):
    the text from ``a``'s start to ``b``'s end with both replacements; ``None`` when they overlap or are not
    on one line."""
    if not (a.line == a.end_line == b.line == b.end_line) or a.end_col > b.col:
        return None
    text = source.splitlines()[a.line - 1]
    return Edit(a.file, a.line, a.col, a.line, b.end_col, a.text + text[a.end_col - 1:b.col - 1] + b.text)


def pair_edits(source: str, singles: Sequence[Edit]) -> list[Edit]:
    """The two-token corrections (module docstring) made of ``singles``, the ranked one-token corrections of
    the culprit line; ``[]`` when fewer than two lie on one line."""
    line = next((e.line for e in singles if e.line == e.end_line), 0)
    pool = [e for e in singles if e.line == e.end_line == line][:PAIR_FROM]
    ranked: list[tuple[int, int, Edit]] = []
    for i, a in enumerate(pool):
        for j in range(i + 1, len(pool)):
            first, second = sorted((a, pool[j]), key=lambda e: e.col)
            e = joined(source, first, second)
            if e is not None and e.apply(source) not in (x.apply(source) for _, _, x in ranked):
                ranked.append((i + j, i, e))
    return [e for _, _, e in sorted(ranked, key=lambda r: (r[0], r[1]))][:MAX_PAIRS]


__all__ = ["MAX_PAIRS", "PAIR_FROM", "joined", "pair_edits"]
