"""Incremental equals clean (issue: integrity): after any sequence of edits a
user makes between runs, an incremental ``doit verify`` writes the same
report files as a from-scratch run on a copy of the inputs.

The edits and the comparison live in ``tests/_incremental.py``;
``bench/incremental_equivalence.py`` runs random sequences of them (hundreds;
one in its smoke mode, which the suite runs: tests/bench/test_bench_smoke_live.py).
This file checks the harness itself.
"""
from __future__ import annotations

from pathlib import Path

import _incremental as inc

# The random edit sequences themselves run in the suite as the smoke run of
# ``bench/incremental_equivalence.py`` (tests/bench/test_bench_smoke_live.py), which fails on any mismatch;
# this file keeps the harness honest.


def test_every_edit_changes_an_input(tmp_path: Path) -> None:
    """Each edit of the harness changes some input file (an edit that changes
    nothing would make the equivalence test pass without testing)."""
    for k, edit in enumerate(inc.EDITS):
        if edit is inc.edit_revert:  # undoes the edits before it: nothing on a fresh workspace (tested below)
            continue
        ws = inc.make_workspace(tmp_path / f"w{k}")
        before = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        edit(ws, 1)
        after = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        assert before != after, edit.__name__


def test_the_revert_edit_gives_back_the_inputs_as_written(tmp_path: Path) -> None:
    """``edit_revert`` undoes every other edit: after all of them and a
    revert, each input file holds what a fresh workspace holds, and the
    files the edits added are gone."""
    fresh = inc.make_workspace(tmp_path / "fresh")
    ws = inc.make_workspace(tmp_path / "ws")
    for k, edit in enumerate(inc.EDITS):
        edit(ws, k + 1)
    if not (ws / "contracts/logger.rcl").exists():
        inc.edit_contract_file(ws, 7)  # so that there is an added file to delete
    assert (ws / "contracts/logger.rcl").exists()
    inc.edit_revert(ws, 0)
    files = {p.relative_to(ws): p.read_bytes() for p in ws.rglob("*") if p.is_file()}
    assert files == {p.relative_to(fresh): p.read_bytes() for p in fresh.rglob("*") if p.is_file()}
