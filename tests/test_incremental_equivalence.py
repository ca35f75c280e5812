"""Incremental equals clean (issue: integrity): after any sequence of edits a
user makes between runs, an incremental ``doit verify`` writes the same
report files as a from-scratch run on a copy of the inputs.

The edits and the comparison live in ``tests/_incremental.py``; this test
runs a few random sequences (Hypothesis chooses the edits and their
arguments), ``bench/incremental_equivalence.py`` runs hundreds.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import _incremental as inc

#: Sequences run here (each edit costs two doit runs of a few seconds); the suite's smoke run of
#: ``bench/incremental_equivalence.py`` (tests/test_bench_smoke_live.py: its exit status) checks one more, with its
#: own seed, and fails on any mismatch.
SEQUENCES = 1


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The cut-down workspace, verified once (the start of every sequence)."""
    root = inc.make_workspace(tmp_path_factory.mktemp("base") / "ws")
    proc = inc.verify(root)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return root


_edits = st.lists(st.tuples(st.sampled_from(inc.EDITS), st.integers(0, 1000)), min_size=1, max_size=2)


@settings(max_examples=SEQUENCES, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(sequence=_edits)
def test_incremental_report_equals_clean_report(verified: Path, tmp_path_factory: pytest.TempPathFactory,
                                                sequence: list[tuple[inc.Edit, int]]) -> None:
    base = tmp_path_factory.mktemp("seq")
    ws = base / "inc" / "ws"
    shutil.copytree(verified, ws, symlinks=True)  # with its artifacts and doit state: the next run is incremental
    done = []
    for edit, k in sequence:
        done.append(edit(ws, k))
        diffs = inc.compare(ws, base / "clean" / "ws")
        assert not diffs, f"after {done}:\n" + "\n".join(diffs)


def test_every_edit_changes_an_input(tmp_path: Path) -> None:
    """Each edit of the harness changes some input file (an edit that changes
    nothing would make the equivalence test pass without testing)."""
    for k, edit in enumerate(inc.EDITS):
        ws = inc.make_workspace(tmp_path / f"w{k}")
        before = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        edit(ws, 1)
        after = {p: p.read_bytes() for p in ws.rglob("*") if p.is_file()}
        assert before != after, edit.__name__
