"""Realizability of a contract that quantifies over an output sequence
(docs/semantics.md, "Realizability over bounded output sequences"): decided
over the lengths the interface carries (a bounded sequence, a fixed array),
or by a witness (an implementation's outputs); in both cases the query kept
is one cvc5 decides too, where the quantifier over the sequence left it
``unknown`` (so ``--strict`` could never pass).  The health stage reads the
bound from the message definition the mapping names."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.app.pipeline import health_findings
from rclverify.calculus.health.bounded import Bound
from rclverify.calculus.health.realizable import realizability_findings
from rclverify.lang.parser import parse_formula, parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics import world
from rclverify.stages.crosscheck.cvc5_decide import decide
from rclverify.stages.provenance import stage_inputs
from rclverify.stages.workspace import Workspace

#: Every item at most the input, one item equal to it: realizable (``<in.x>``).
ECHO = """
node S { inputs( x : INTEGER ) outputs( ys : seq(INTEGER) )
  assume( 0 <= in.x and in.x <= 5 )
  guarantee( forall(y in out.ys | y <= in.x) )
  guarantee( exists(y in out.ys | y == in.x) ) }
"""
#: Every item below the input, one item equal to it: not realizable, whatever the length.
BELOW = ECHO.replace("y <= in.x", "y < in.x")
#: Three different items: realizable only with room for three.
THREE = """
node T { inputs( x : INTEGER ) outputs( ys : seq(INTEGER) ) assume( TRUE )
  guarantee( exists(a in out.ys | a == 1) and exists(b in out.ys | b == 2) and exists(c in out.ys | c == in.x) )
  guarantee( 2 < in.x -> forall(y in out.ys | y <= in.x) ) }
"""


def _one(text: str, node: str, **kw: object):  # type: ignore[no-untyped-def]
    world.fresh()
    found = realizability_findings(check([parse_text(text, "s.rcl")]), node, **kw)  # type: ignore[arg-type]
    assert len(found) == 1, found
    return found[0]


def test_a_bounded_output_sequence_is_decided_both_ways_and_cvc5_agrees() -> None:
    ok = _one(ECHO, "S", bounds={"ys": Bound(3)})
    assert ok.status == "ok" and "at most 3 items), written out item by item" in ok.explanation
    assert decide(ok.smt2).answer == "unsat"  # the second solver decides the kept query: --strict can pass
    bad = _one(BELOW, "S", bounds={"ys": Bound(3)})
    assert bad.status == "problem" and bad.core == ["guarantee 1 (s.rcl:4:3)", "guarantee 2 (s.rcl:5:3)"]
    assert decide(bad.smt2).answer == "sat"
    # control: without a bound Z3 still finds the input with no answer, but its query over the sequence sort
    # is beyond cvc5 (unknown: the second solver cannot confirm it, and --strict fails)
    free = _one(BELOW, "S")
    assert free.status == "problem" and "written out" not in free.explanation
    assert decide(free.smt2).answer == "unknown"


def test_an_unbounded_output_sequence_is_decided_by_an_answer_of_a_simple_shape() -> None:
    """``<in.x>`` answers ECHO: the finding says it was decided by that witness, and cvc5 decides its query;
    no such answer exists for BELOW (not realizable) or THREE (three items needed: undecided unbounded)."""
    w = _one(ECHO, "S")
    assert w.status == "ok" and "Decided by a witness: the answer out.ys = <in.x>" in w.message
    assert w.witness == {"out.ys": "<in.x>"} and decide(w.witness_smt2).answer == "unsat"
    assert _one(BELOW, "S").witness is None
    world.fresh()
    assert realizability_findings(check([parse_text(THREE, "s.rcl")]), "T") == []


def test_the_bound_decides_where_the_length_matters() -> None:
    """Three different items fit in at most 3 (and in exactly 3), not in at most 2 or exactly 2; unbounded
    the contract is not decided at all (previous test)."""
    assert _one(THREE, "T", bounds={"ys": Bound(3)}).status == "ok"
    assert _one(THREE, "T", bounds={"ys": Bound(3, fixed=True)}).status == "ok"
    short = _one(THREE, "T", bounds={"ys": Bound(2)})
    assert short.status == "problem" and "at most 2 items" in short.explanation
    assert _one(THREE, "T", bounds={"ys": Bound(2, fixed=True)}).status == "problem"


def test_a_bounded_natural_sequence_has_its_items_typed() -> None:
    """Unbounded, a seq(NATURAL)'s items are not typed and no ``ok`` may be claimed
    (tests/calculus/test_realizable.py); written out, every item is typed ``>= 0``, so a contract asking for a
    negative item is decided not realizable, and one asking for a non-negative one realizable."""
    neg = ("node C { inputs( x : INTEGER ) outputs( y : seq(NATURAL) ) assume( TRUE ) "
           "guarantee( exists(v in INTEGER | v in out.y and v < 0) ) }")
    assert _one(neg, "C", bounds={"y": Bound(2)}).status == "problem"
    assert _one(neg.replace("v < 0", "v >= 0"), "C", bounds={"y": Bound(2)}).status == "ok"


def test_a_witness_decides_and_a_wrong_one_does_not() -> None:
    w = _one(ECHO, "S", implementation={"ys": parse_formula("<in.x>")})
    assert w.status == "ok" and "Decided by a witness" in w.message and w.witness == {"out.ys": "<in.x>"}
    assert decide(w.witness_smt2).answer == "unsat"  # the witness query has no quantifier over the outputs
    # controls: an implementation whose second item breaks guarantee 1, and one longer than the interface
    # carries, are no witness (the quantified query decides instead, as without them)
    wrong = _one(ECHO, "S", implementation={"ys": parse_formula("<in.x, in.x + 1>")})
    assert wrong.status == "ok" and "witness" not in wrong.message and wrong.witness is None
    long = _one(ECHO, "S", implementation={"ys": parse_formula("<in.x, in.x>")}, bounds={"ys": Bound(1)})
    assert long.status == "ok" and "witness" not in long.message and "at most 1 item)" in long.explanation
    # and no witness makes an unrealizable contract realizable
    assert _one(BELOW, "S", implementation={"ys": parse_formula("<in.x>")}).status == "problem"


def _workspace(root: Path, field: str) -> Workspace:
    """A one-node workspace whose output ``ys`` is carried by ``robot_msgs/Picks``'s ``items`` of type ``field``."""
    (root / "contracts").mkdir(parents=True)
    (root / "backends" / "monitors").mkdir(parents=True)
    (root / "msg" / "robot_msgs" / "msg").mkdir(parents=True)
    (root / "contracts" / "s.rcl").write_text(ECHO.replace(
        "outputs( ys : seq(INTEGER) )",
        "outputs( ys : seq(INTEGER) )\n  topics( std_msgs/Int32 x matches(in.x), robot_msgs/Picks picks matches(out.ys) )"))
    (root / "contracts" / "plan.yaml").write_text(
        "name: bounded\ncontracts:\n  - contracts/s.rcl\nconnections: []\nenvironment: {}\n")
    (root / "backends" / "monitors" / "mapping.yaml").write_text(
        "msg_dirs: [msg]\ntopics:\n  picks: {fields: [items]}\n  x: {fields: [data]}\n")
    (root / "msg" / "robot_msgs" / "msg" / "Picks.msg").write_text(f"{field} items\n")
    return Workspace(root)


def test_the_health_stage_reads_the_bound_from_the_message_definition(tmp_path: Path) -> None:
    """``int32[<=3]`` bounds the output: the health stage's finding is decided over it, and the mapping and
    the ``.msg`` are inputs of the node's health record and task; control: ``int32[]`` bounds nothing."""
    pytest.importorskip("rosbags")  # the ros extra reads the message definitions
    ws = _workspace(tmp_path / "bounded", "int32[<=3]")
    [f] = [f for f in health_findings(ws, "S") if f.check == "realizable"]
    assert f.status == "ok" and "(at most 3 items), written out item by item" in f.explanation
    files = ["backends/monitors/mapping.yaml", "msg/robot_msgs/msg/Picks.msg"]
    assert stage_inputs(ws, "S", "health")[1:] == files and list(ws.index.bound_inputs["S"]) == files
    free = _workspace(tmp_path / "free", "int32[]")
    [g] = [f for f in health_findings(free, "S") if f.check == "realizable"]
    assert g.status == "ok" and "written out" not in g.explanation and g.witness == {"out.ys": "<in.x>"}
    assert stage_inputs(free, "S", "health")[1:] == files  # an edit that adds a bound checks it again
