"""A repair candidate edited inside one node's clauses is checked as that
node alone, spliced into the checked system (diagnosis/splice.py, issue
44): the system it gives must be the one parsing and checking every file
again gives (the oracle: the full path, run on the same edited text), the
edited node's locations included; any other edit is left to the full path."""
from __future__ import annotations

import dataclasses
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.diagnosis import recheck
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.splice import FULL, spliced_system
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build
from rclverify.stages.workspace import Workspace

A = """context {
  Mode : {idle, busy} ;
  Limit : REAL = 10 ;
}

node Sensor {
  inputs( r : REAL )
  outputs( d : REAL, m : Mode )
  assume( 0 <= in.r and in.r <= 30 )
  guarantee( out.d == 2 * in.r )
  guarantee( in.r > 20 -> out.m == busy )
}

node Filter { inputs( d : REAL ) outputs( f : REAL )
  assume( 0 <= in.d and in.d <= Limit )
  guarantee( out.f <= in.d ) guarantee( 0 <= out.f ) }
"""
B = """node Planner {
  inputs( f : REAL, m : Mode )
  outputs( v : REAL )
  assume( in.f <= 100 )
  guarantee( forall(i in NATURAL | i <= 3 -> out.v >= i - 4) )
  guarantee( in.m == idle -> out.v == 0 )
}
"""


@pytest.fixture()
def ws(tmp_path: Path) -> Workspace:
    (tmp_path / "contracts").mkdir()
    (tmp_path / "contracts" / "a.rcl").write_text(A, encoding="utf-8")
    (tmp_path / "contracts" / "b.rcl").write_text(B, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(
        "name: splice\ncontracts:\n  - contracts/a.rcl\n  - contracts/b.rcl\n", encoding="utf-8")
    w = Workspace(tmp_path)
    w.checked  # noqa: B018 - loads and checks
    return w


def _full(ws: Workspace, edit: Edit) -> Any:
    specs = []
    try:
        for rel in ws.plan.contracts:
            text = recheck.source_text(ws, rel)
            specs.append(parse_text(edit.apply(text) if rel == edit.file else text, rel))
        c = check(specs)
        return c, build(c, ws.plan.connections)
    except (RclError, KeyError, ValueError):
        return None


def _locs(x: Any, out: list[Any]) -> list[Any]:
    if isinstance(x, tuple):
        for y in x:
            _locs(y, out)
    elif dataclasses.is_dataclass(x) and not isinstance(x, type):
        for f in dataclasses.fields(x):
            v = getattr(x, f.name)
            if type(v).__name__ == "Loc":
                out.append(dataclasses.astuple(v))
            else:
                _locs(v, out)
    return out


def _same(ws: Workspace, quick: Any, full: Any) -> None:
    assert (quick is None) == (full is None)
    if quick is None:
        return
    (cq, mq), (cf, mf) = quick, full
    assert mq == mf and cq.env == cf.env and list(cq.nodes) == list(cf.nodes)
    for name in cf.nodes:
        q, f = cq.nodes[name], cf.nodes[name]
        assert (q.node, q.inputs, q.outputs, q.units) == (f.node, f.inputs, f.outputs, f.units), name
        if q is not ws.checked.nodes[name]:  # the edited node: its locations are the whole file's too
            assert _locs(q.node, []) == _locs(f.node, []), name


def _edit_at(ws: Workspace, rel: str, old: str, new: str, nth: int = 0) -> Edit:
    text = recheck.source_text(ws, rel)
    at = -1
    for _ in range(nth + 1):
        at = text.index(old, at + 1)
    line = text.count("\n", 0, at) + 1
    col = at - (text.rfind("\n", 0, at) + 1) + 1
    end = at + len(old)
    return Edit(rel, line, col, text.count("\n", 0, end) + 1, end - (text.rfind("\n", 0, end) + 1) + 1, new)


@pytest.mark.parametrize("rel, old, new", [
    ("contracts/a.rcl", "30", "25"),                                         # a bound
    ("contracts/a.rcl", "out.d == 2 * in.r", "(out.d == 2 * in.r) and (out.d <= 10)"),
    ("contracts/a.rcl", "guarantee( 0 <= out.f )", "guarantee( 0 <= out.f )\n  guarantee( out.f <= 5 )"),
    ("contracts/a.rcl", "in.r > 20 -> out.m == busy", "in.r > 20 ->\n    out.m == busy"),  # a line more, mid-node
    ("contracts/b.rcl", "i <= 3", "i <= 2 and i >= 1"),
    ("contracts/b.rcl", "out.v == 0", "out.v == 0 and out.v <= Limit"),
])
def test_an_edit_inside_a_node_gives_the_system_the_whole_file_gives(ws: Workspace, rel: str, old: str,
                                                                    new: str) -> None:
    edit = _edit_at(ws, rel, old, new)
    quick = spliced_system(ws, edit, recheck.source_text(ws, rel))
    assert quick is not FULL and quick is not None
    _same(ws, quick, _full(ws, edit))
    _same(ws, recheck.edited_system(ws, edit), _full(ws, edit))


@pytest.mark.parametrize("rel, old, new, expect", [
    ("contracts/a.rcl", "out.m == busy", "out.m == 3", None),               # ill-typed: the candidate does not check
    ("contracts/a.rcl", "out.d == 2 * in.r", "out.d == 2 * in.q", None),     # unknown input
    ("contracts/a.rcl", "outputs( d : REAL, m : Mode )", "outputs( d : REAL )", FULL),  # the interface changes
    ("contracts/a.rcl", "Limit : REAL = 10", "Limit : REAL = 20", FULL),      # a context
    ("contracts/a.rcl", "busy )\n}\n\nnode Filter", "busy )\n}\nnode Filter", FULL),  # across two nodes
    ("contracts/a.rcl", "guarantee( 0 <= out.f ) }", "guarantee( 0 <= out.f ) }\nnode X { inputs( z : REAL ) "
                                                     "outputs( w : REAL ) guarantee( out.w == 1 ) ", FULL),
    ("contracts/b.rcl", "out.v >= i - 4", "out.v >= i - 4 /* open", FULL),   # does not parse alone
])
def test_other_edits_are_left_to_the_whole_file_or_fail_as_there(ws: Workspace, rel: str, old: str, new: str,
                                                                 expect: Any) -> None:
    edit = _edit_at(ws, rel, old, new)
    quick = spliced_system(ws, edit, recheck.source_text(ws, rel))
    assert quick is expect
    _same(ws, recheck.edited_system(ws, edit), _full(ws, edit))


def test_random_edits_of_literals_and_operators_agree_with_the_whole_file(ws: Workspace) -> None:
    """Every numeric literal and comparison of every clause, replaced at random (some
    replacements ill-typed), 60 edits: the spliced system is the full path's, or both fail."""
    rng = random.Random(44)
    sites = []
    for rel in ws.plan.contracts:
        text = recheck.source_text(ws, rel)
        for tok in ("30", "20", "2", "100", "3", "4", "<=", "==", ">", "busy", "idle", "in.r", "out.v"):
            at = text.find(tok)
            while at != -1:
                if text.rfind("node", 0, at) != -1:  # inside some node, not the context
                    sites.append((rel, tok, text[:at].count(tok)))
                at = text.find(tok, at + 1)
    for _ in range(60):
        rel, tok, nth = rng.choice(sites)
        new = rng.choice(["7", "0.5", ">=", "<", "busy", "TRUE", "in.r", "out.d", "(1 + 2)", "Limit"])
        edit = _edit_at(ws, rel, tok, new, nth)
        full = _full(ws, edit)
        got = recheck.edited_system(ws, edit)
        _same(ws, got, full)
