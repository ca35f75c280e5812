"""Lifecycle scopes and transition deadlines in RCL (issue 110): syntax, round trip through the
printer, LaTeX, located type errors and the ``W-lifecycle-unscoped`` lint, each with its control."""
from __future__ import annotations

from fractions import Fraction

import pytest

from rclverify.lang.errors import RclError
from rclverify.lang.latex import to_latex
from rclverify.lang.lifecycle import scope_of, transition_topic
from rclverify.lang.lint import lint
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.timing import seconds
from rclverify.lang.typecheck import check

TOPICS = ("topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level),\n"
          "          lifecycle_msgs/TransitionEvent battery/transition_event )")
PLAIN = "topics( std_msgs/Float64 request matches(in.request), std_msgs/Float64 level matches(out.level) )"


def node(*items: str, topics: str = TOPICS) -> str:
    body = "\n  ".join(items)
    return (f"node Battery {{\n  inputs( request : REAL )\n  outputs( level : REAL )\n  {topics}\n"
            f"  assume( in.request >= 0 )\n  {body}\n}}\n")


SCOPED = node("guarantee( out.level >= in.request ) while inactive or active",
              "G( out.level >= 0 ) triggered by in.request within 200 ms while inactive or active",
              "ready within 200 ms of activate", "ready within 1.5 s of configure")


def errors_of(text: str) -> list[str]:
    with pytest.raises(RclError) as exc:
        check([parse_text(text, "f.rcl")])
    return [str(d) for d in exc.value.diagnostics if d.severity == "error"]


def test_scopes_and_transition_deadlines_are_read() -> None:
    n = parse_text(SCOPED, "f.rcl").nodes[0]
    g1, g2 = n.guarantees
    assert g1.scope is not None and g1.scope.states == ("inactive", "active")
    assert (g1.scope.loc.line, g1.scope.loc.col) == (7, 40)
    assert g2.scope is not None and g2.scope.states == ("inactive", "active")
    assert g2.deadline is not None and g2.trigger is not None  # the scope comes after the trigger and deadline
    assert [(t.transition, seconds(t.deadline)) for t in n.transitions] == [
        ("activate", Fraction(1, 5)), ("configure", Fraction(3, 2))]
    assert transition_topic(n) is not None and transition_topic(n).field == "battery/transition_event"  # type: ignore[union-attr]
    assert scope_of(n, g2) == ("inactive", "active")
    check([parse_text(SCOPED, "f.rcl")])  # no error


def test_an_unscoped_guarantee_keeps_its_meaning() -> None:
    """Unscoped on a lifecycle node: judged while active (the default scope); on a plain node: no scope
    (every state).  A contract written before scopes parses to the same tree as before."""
    managed = parse_text(node("guarantee( out.level >= in.request )"), "f.rcl").nodes[0]
    plain = parse_text(node("guarantee( out.level >= in.request )", topics=PLAIN), "f.rcl").nodes[0]
    assert managed.guarantees[0].scope is None and managed.transitions == ()
    assert scope_of(managed, managed.guarantees[0]) == ("active",)
    assert scope_of(plain, plain.guarantees[0]) is None and transition_topic(plain) is None


def test_the_printer_round_trips_scopes_and_deadlines() -> None:
    spec = parse_text(SCOPED, "f.rcl")
    text = to_rcl(spec)
    assert "guarantee( out.level >= in.request ) while inactive or active\n" in text
    assert "triggered by in.request within 200 ms while inactive or active\n" in text
    assert "  ready within 200 ms of activate\n  ready within 1.5 s of configure\n" in text
    assert parse_text(text, "f.rcl") == spec
    unscoped = parse_text(node("guarantee( out.level >= in.request )"), "f.rcl")
    assert "while" not in to_rcl(unscoped) and "ready" not in to_rcl(unscoped)  # control


def test_latex_shows_scopes_and_deadlines() -> None:
    tex = to_latex(parse_text(SCOPED, "f.rcl"), document=False)
    assert r"while \textsf{inactive} or \textsf{active}" in tex
    assert r"lifecycle & ready within 200~\textrm{ms} of \textsf{activate} \\" in tex
    assert "while" not in to_latex(parse_text(node("guarantee( out.level >= in.request )"), "f.rcl"), document=False)


def test_a_scope_or_deadline_on_a_node_that_is_not_managed_is_located() -> None:
    errs = errors_of(node("guarantee( out.level >= in.request ) while active", "ready within 200 ms of activate",
                          topics=PLAIN))
    assert errs[0].startswith("f.rcl:6:40: error: guarantee 1 is scoped to lifecycle states ('while active'), "
                              "but node Battery is not a lifecycle node: name its transition topic")
    assert errs[1].startswith("f.rcl:7:3: error: a transition deadline ('ready within 200 ms of activate'), but node "
                              "Battery is not a lifecycle node")
    assert len(errs) == 2


def test_unknown_states_transitions_and_units_are_located() -> None:
    errs = errors_of(node("guarantee( out.level >= in.request ) while running",
                          "guarantee( out.level >= 0 ) while active or active",
                          "ready within 200 of activate", "ready within 2 ms of jump",
                          "ready within 3 kg of configure", "ready within 1 s of activate"))
    assert errs == [
        "f.rcl:7:40: error: guarantee 1: 'running' is not a lifecycle state a guarantee can be scoped to "
        "(states: unconfigured, inactive, active, finalized)",
        "f.rcl:8:31: error: guarantee 2: state active is named twice in its scope",
        "f.rcl:9:9: error: transition deadline 'within 200' needs a unit of time and a positive amount, "
        "e.g. 'ready within 200 ms of activate'",
        "f.rcl:10:3: error: 'jump' is not a lifecycle transition "
        "(transitions: configure, activate, deactivate, cleanup, shutdown)",
        "f.rcl:11:9: error: transition deadline 'within 3 kg' needs a unit of time and a positive amount, "
        "e.g. 'ready within 3 ms of configure'",
        "f.rcl:12:3: error: the activate transition of node Battery is bounded twice (first at f.rcl:9:3)"]


def test_while_after_a_deadline_without_unit_is_the_keyword() -> None:
    """``within 200 while active``: ``while`` is not read as the deadline's unit."""
    errs = errors_of(node("guarantee( out.level >= in.request ) triggered by in.request within 200 while active"))
    assert len(errs) == 1 and "deadline 'within 200' has no unit" in errs[0]
    n = parse_text(node("guarantee( out.level >= in.request ) triggered by in.request within 200 while active"),
                   "f.rcl").nodes[0]
    assert n.guarantees[0].scope is not None and n.guarantees[0].deadline.unit is None  # type: ignore[union-attr]


def test_words_of_the_new_forms_stay_names_elsewhere() -> None:
    text = ("node Battery {\n  inputs( ready : REAL, of : REAL )\n  outputs( level : REAL )\n"
            "  guarantee( out.level >= in.ready + in.of )\n}\n")
    check([parse_text(text, "f.rcl")])


def test_lint_names_an_unscoped_guarantee_of_a_lifecycle_node() -> None:
    diags = [d for d in lint(parse_text(node("guarantee( out.level >= in.request )",
                                             "guarantee( out.level >= 0 ) while active"), "f.rcl"))
             if d.code == "W-lifecycle-unscoped"]
    assert [str(d) for d in diags] == [
        "f.rcl:7:3: warning: guarantee 1 of Battery: Battery is a lifecycle node (it names its transition topic "
        "battery/transition_event); an unscoped guarantee is judged only while the node is active; write "
        "'while active' after it to say so, or the states it holds in"]
    plain = lint(parse_text(node("guarantee( out.level >= in.request )", topics=PLAIN), "f.rcl"))
    assert not [d for d in plain if d.code == "W-lifecycle-unscoped"]  # control: not a lifecycle node


def test_the_guarantees_of_one_node_share_one_scope() -> None:
    errs = errors_of(node("guarantee( out.level >= in.request )", "guarantee( out.level >= 0 ) while inactive or active"))
    assert errs == ["f.rcl:8:31: error: guarantee 2 is judged while inactive or active, guarantee 1 while active: the "
                    "guarantees of one lifecycle node share one scope (an unscoped one: while active), since the "
                    "monitors ask a node's questions by its state"]
    check([parse_text(node("guarantee( out.level >= in.request )", "guarantee( out.level >= 0 ) while active"),
                      "f.rcl")])  # control: unscoped is while active


def test_the_editor_completes_every_keyword_of_the_grammar() -> None:
    """The language server's completion (tools/lsp/complete.py ``KEYWORDS``) offers every word rcl.lark
    quotes, the new ``while``, ``ready`` and ``of`` among them; the short forms ``A``/``G``, ``abs``, ``sqrt``, ``sin``, ``cos`` and
    ``x`` (and a comment's example name) are the only words left out."""
    import re

    from rclverify.lang.parser import grammar_text
    from rclverify.tools.lsp.complete import KEYWORDS
    words = set(re.findall(r'"([A-Za-z_]+)"', grammar_text()))
    assert {"while", "ready", "of"} <= words
    assert words - set(KEYWORDS) == {"A", "G", "abs", "sqrt", "sin", "cos", "x", "RadStat"}
