"""The random oracle of the code repairs (issue 111; bench/repair_oracle.py, docs/diagnosis.md "The random
oracle of the code repairs"): generated nodes with one seeded one-token slip, the tool run on each as the
pipeline runs it (the property tests, then the checked repairs), every repair offered judged by brute
force over the input domain.  Asserted: no repair the oracle rejects is ever offered, and every case offers
one (the figure of the first repair right is the bench's to print).  The control: the oracle rejects each
slipped function and a repair that breaks the other guarantee, so a wrong repair would be seen."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

from repair_oracle import cases, right, run  # noqa: E402

pytestmark = pytest.mark.slow  # the property tests of 8 generated nodes, each repair checked by them

SEED, CASES = 3, 8


@pytest.fixture(scope="module")
def results() -> list:  # type: ignore[type-arg]
    return run(SEED, CASES)


def test_never_a_wrong_repair(results: list) -> None:  # type: ignore[type-arg]
    assert len(results) == CASES
    wrong = [(c.family, c.slip, code) for c, o in results for code, ok in zip(o.offered, o.judged) if not ok]
    assert wrong == []
    # each case: the slip found at the function's line and a repair offered, the first one right
    assert [(c.family, bool(o.cause), bool(o.judged) and o.judged[0]) for c, o in results] == \
        [(c.family, True, True) for c, _ in results]


def test_control_the_oracle_rejects_the_slips_and_a_repair_that_breaks_a_guarantee() -> None:
    made = cases(SEED, CASES)
    assert all(right(c, c.code) and not right(c, c.slipped) for c in made)
    # a threshold node repaired on one guarantee and broken on the other: `x < 3` -> `x < 10` (cf. Gate)
    gate = next(c for c in cases(11, 30) if c.family == "threshold")
    assert not right(gate, gate.code.replace('{"ok": ', '{"ok": True or '))
    assert not right(gate, gate.code.replace('{"ok": ', '{"ok": False and '))


def test_two_slips_on_one_line_are_repaired_with_two_tokens_and_never_wrongly() -> None:
    """diagnosis/pair_edits.py on generated nodes with two slips on one line (``--two``): each case repaired,
    no repair the oracle rejects.  The control: no one-token correction of the line makes any case right
    (the generator keeps only those), so each repair offered is a pair."""
    from repair_oracle import _one_token_fixes
    got = run(5, 3, two=True)
    assert all(not _one_token_fixes(c) for c, _ in got)
    assert [(bool(o.cause), o.judged[:1]) for _, o in got] == [(True, [True])] * 3
    assert all(all(o.judged) for _, o in got)
