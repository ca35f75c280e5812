"""The question an input message raises in a deadline monitor (:class:`~.deadlines.DeadlineMonitor`;
docs/semantics.md, "Deadlines"), and the obligations it opens.

**Only accepted inputs are obligations**: the node's assumption
is judged on the trigger's inputs; a trigger whose inputs violate it (or
whose inputs are not all observed yet at its stamp, however late it was
heard, or whose assumption cannot be decided) gets no deadline verdict and is counted apart
(:attr:`.deadline_records.DeadlineResult.unaccepted`): a node is not obliged to answer an
input its contract does not accept, so a ``true`` there would be evidence
of nothing and a ``false`` a false alarm.  Formulas are judged as the
untimed monitor judges them (:func:`rclverify.semantics.floatsem.judge`: exact,
the node's double arithmetic, a declared tolerance).

An input message stamped at or after every one heard is judged on the inputs as they stand; one heard after
a message stamped later, on the inputs in force at its stamp (:func:`inputs_at`).
"""
from __future__ import annotations

from collections import deque
from typing import Mapping, Protocol

from rclverify.semantics.floatsem import Tolerance, judge
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.questions import Question, QuestionStream
from rclverify.backends.monitors.deadline_records import DeadlineResult
from rclverify.backends.monitors.late import value_at


class AskingMonitor(Protocol):
    """What this module reads and moves of a deadline monitor (:class:`~.deadlines.DeadlineMonitor`)."""

    checked: Checked
    node: CheckedNode
    tolerance: Tolerance | None
    assumption: tuple[ast.Expr, ...]
    timed: list[tuple[int, ast.Clause, str, frozenset[str], float]]
    needed: list[str]
    stream: QuestionStream
    values: dict[str, object]
    before_first: dict[str, deque[tuple[int, object]]]
    invalid: dict[str, str]
    result: DeadlineResult

    def _oblige(self, k: int, ev: Event, ns: int, inputs: dict[str, object]) -> None: ...


def ask(mon: AskingMonitor, ev: Event, ns: int, changed: list[str], own: Mapping[str, object], late: bool) -> None:
    """Input message ``ev`` stamped ``ns`` (integer ns), which set the keys ``changed`` (``own``: the values
    it set of the inputs a message stamped after it had set; ``late``: stamped before a message heard
    already): the question it raises is asked (when every input has a value) and each guarantee it
    triggers opens its obligation (:meth:`~.deadlines.DeadlineMonitor._oblige`) when the node's assumption
    accepts the inputs (:func:`refused`), else is counted unaccepted."""
    stamp = ns / 1e9
    mine = {c: own.get(c, mon.values[c]) for c in changed if c.startswith("in.") and c not in mon.invalid}
    if mon.stream.at(stamp) is None:
        for key, v in mine.items():
            mon.before_first.setdefault(key, deque(maxlen=64)).append((ns, v))
    inputs = (inputs_at(mon, stamp, ns, mine) if late and not mon.stream.forgot else
              {key: v for key, v in mon.values.items() if key.startswith("in.")})
    missing = [k for k in mon.needed if k not in inputs]
    unread = [why for k, why in mon.invalid.items() if k in mon.needed]
    refusal = (("incomplete input", "no value yet for " + ", ".join(missing)) if missing else
               ("undecided", unread[0]) if unread else refused(mon, inputs))
    if not missing:
        mon.stream.ask(Question(ev, stamp, inputs, owed=refusal is None))
    triggered = [t for t in mon.timed if t[2] in changed]
    if not triggered:
        return
    for k, cl, trig, _, d in triggered:
        if refusal is None:
            mon._oblige(k, ev, ns, inputs)
            continue
        why, reason = refusal
        mon.result.unaccepted[why] += 1
        if mon.result.first_unaccepted is None:
            mon.result.first_unaccepted = {"guarantee": k, "where": ev.where, "stamp": stamp, "why": why,
                                            "reason": reason}


def inputs_at(mon: AskingMonitor, stamp: float, ns: int, mine: Mapping[str, object]) -> dict[str, object]:
    """The inputs in force at ``stamp`` (s; ``ns`` the same in integer ns) of an input message heard
    after one stamped later, which set ``mine``: those of the latest question at or before its stamp,
    or before the first question those its messages stamped at or before it set, with its own
    values (docs/semantics.md, "Deadlines": a trigger before every input has a value at its stamp
    raises no question and gets no deadline verdict, however late it was heard; the verdict
    engine reads it so, :meth:`.late.Late._late_input`)."""
    q = mon.stream.at(stamp)
    got = dict(q.inputs) if q is not None else {
        k: v for k, h in mon.before_first.items() if (v := value_at(h, ns)) is not None}
    got.update(mine)
    return got


def refused(mon: AskingMonitor, inputs: Mapping[str, object]) -> tuple[str, str] | None:
    """Why the node's assumption does not accept ``inputs`` (``(kind,
    reason)``, kind one of :data:`~.deadline_records.UNACCEPTED`), ``None`` when it does."""
    for formula in mon.assumption:
        j = judge(formula, mon.checked, mon.node, inputs, mon.tolerance)
        if j.truth is True:
            continue
        if j.truth is False:
            return "assumption violated", f"assumption {expr_to_rcl(formula)} is false of the trigger's inputs"
        if j.reason.startswith("no value for"):
            return "incomplete input", j.reason
        return "undecided", f"assumption {expr_to_rcl(formula)} undecided: {j.reason}"
    return None


__all__ = ["AskingMonitor", "ask", "inputs_at", "refused"]
