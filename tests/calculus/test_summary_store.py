"""Cone summaries kept on disk (calculus/summary.py, ``use_directory``):
a summary another process of the run or an earlier run made is read, not
made again, and reads as the very summary made fresh; a kept file that is
damaged, of another node or names a premise the cone has not is made again.
The oracle is the summary made with nothing kept."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from _chain import chain_rcl
from rclverify.calculus import summary, summary_store
from rclverify.calculus.compose import environment_conjuncts
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

X0 = {"N0": [parse_formula("0 <= in.x0 and in.x0 <= 50")]}
N = 12


def _fresh_process() -> None:
    """What a new process holds: no summary in memory."""
    summary._MEMO.update({"key": None, "summaries": {}, "keys": {}})
    summary_store._blobs.forget()


def _computed(directory: Path | None, **chain: object) -> tuple[dict[str, summary.Summary | None], dict[str, bytes]]:
    """The summaries of the chain (``chain``: :func:`chain_rcl`'s options) and
    their keys, made as a new process makes them, kept in ``directory``."""
    checked = check([parse_text(chain_rcl(N, bound=300, **chain), "sys.rcl")])  # type: ignore[arg-type]
    model = build(checked)
    summary.use_directory(directory)
    _fresh_process()
    try:
        env = lambda n: environment_conjuncts(checked, model, n)  # noqa: E731
        summary.summary_of(checked, model, f"N{N - 1}", env, X0)
        return dict(summary._MEMO["summaries"]), dict(summary._MEMO["keys"])
    finally:
        summary.use_directory(None)
        _fresh_process()


def _summaries(directory: Path | None) -> dict[str, summary.Summary | None]:
    return _computed(directory)[0]


@pytest.fixture(scope="module")
def reference() -> dict[str, summary.Summary | None]:
    return _summaries(None)


def test_kept_summaries_are_read_and_equal_the_ones_made(tmp_path: Path, reference, monkeypatch) -> None:
    made = _summaries(tmp_path)
    assert made == reference and all(s is not None for s in made.values())
    assert len(list(tmp_path.glob("*.json"))) == N  # N0 .. N11: each one its file
    monkeypatch.setattr(summary_store, "_made", lambda made: pytest.fail(f"{made.node}'s summary made again"))
    assert _summaries(tmp_path) == reference  # every one read from its file


@pytest.mark.parametrize("damage", ["not json", "other node", "unknown premise", "not text"])
def test_a_damaged_file_is_made_again(tmp_path: Path, reference, damage: str) -> None:
    _summaries(tmp_path)
    for f in tmp_path.glob("*.json"):
        node, formula, used, script = json.loads(f.read_text())
        text = {"not json": "{[", "other node": json.dumps(["N99", formula, used, script]),
                "unknown premise": json.dumps([node, formula, used + ["N0 guarantee 99"], script]),
                "not text": json.dumps([node, 1, used, script])}[damage]
        f.write_text(text)
    assert _summaries(tmp_path) == reference
    for f in tmp_path.glob("*.json"):  # each damaged file replaced by the summary made again
        node, formula, used, script = json.loads(f.read_text())
        assert reference[node] is not None and reference[node].formula == formula and reference[node].script == script


def test_an_edit_upstream_changes_every_key_downstream(tmp_path: Path) -> None:
    _summaries(tmp_path)
    before = {f.name for f in tmp_path.glob("*.json")}
    _, keys = _computed(tmp_path, weak={3: 70})
    changed = {n for n, k in keys.items() if f"{k.hex()}.json" not in before}
    assert changed == {f"N{i}" for i in range(3, N)}  # N3's guarantee changed: it and all below it


def test_the_compose_stage_keeps_its_summaries_in_its_workspace_only(tmp_path: Path) -> None:
    """The stage reads and writes ``artifacts/cache/summaries`` of its own
    workspace, and leaves the process keeping summaries in memory only: a
    later computation never writes into a workspace it was not given."""
    from _chain import write_chain
    from rclverify.app.pipeline import stage_check, stage_compose
    from rclverify.stages.workspace import Workspace
    ws = Workspace(write_chain(tmp_path / "ws", 4))
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
    assert summary_store._blobs.directory is None
    assert len(list((tmp_path / "ws/artifacts/cache/summaries").glob("*.json"))) == 3  # N0, N1, N2: read by N1-N3
