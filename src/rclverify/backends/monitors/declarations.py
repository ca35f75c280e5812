"""A node's declarations judged on a recorded run.

A node's ``initially( F )``, ``progress( ... )`` and ``periodic( out.y, P )``
(docs/rcl-language.md, "Progress, initial values and periodic outputs") are
claims about the implementation like its guarantees; each gets a verdict on
every recorded run of the node's ``monitors`` entry, a row of the record's
``details.declarations`` (:meth:`DeclarationResult.rows`).  The run is read
in the stream model of the paper (lines 462-495): a *step* of the node is
one of its input events (a message on a topic ``topics(...)`` binds to an
input, or a call part a link binds to one: a message on the link's topic,
or a call line of a live run's log) that carries an input its contract
reads (its assumption or a guarantee, a quantifier's domain included: a
message no clause reads cannot oblige an answer, e.g. an action's feedback
to a client that only sends goals), and the node *answers* at that step
when one of its output messages comes after it and before its next step.  The assumption is judged on the inputs current at the event
(:func:`rclverify.semantics.floatsem.judge`, as the untimed monitor judges it);
a step at which it holds is *accepted*.

* ``initially( F )``: F judged on the first value each output it reads is
  published with, when that comes before the node's first input event (a
  subscriber has no value of the output before its first message; the value
  the node starts from is observable only when the node publishes it as it
  starts): ``true``/``false``.  A first message after an input may be the
  node's answer, not its initial value: ``inconclusive`` whatever F says of
  it (true there, it would not show that subscribers have F-values before
  the first answer, which is what a proof from ``initially`` assumes;
  false, it would blame a correct node); no message of an output F reads:
  ``pending``.
* ``progress( within K steps )``: never K + 1 accepted steps in a row
  unanswered (a step whose input is not accepted ends the row, as the
  composed system's ``waiting`` counter does, calculus/requirements/transition.py):
  ``false`` at the input event that ends the (K + 1)-th unanswered step;
  ``true`` when at least one accepted step was seen and none broke the
  bound; no accepted step: ``pending`` (the run exercised nothing).  An
  output placed at a stamp older than its publication (``Event.source``: a
  copied stamp, a clock standing still) may answer any step until it was
  published (docs/semantics.md, "Event time"): a row over the bound that
  as many such outputs published within it would bring back within it is
  ``inconclusive`` with why, never ``false`` (generated seed 1147: three
  relays stamping with a paused ``/clock``).
* ``progress( eventually )``: ``true`` when every accepted step is answered
  by a later output; the run ending with an accepted step still unanswered:
  ``inconclusive`` (a finite run never refutes "eventually"); no accepted
  step: ``pending``.
* ``periodic( out.y, N steps )``: as ``progress( within N - 1 steps )``, with
  only a message of ``out.y`` answering.
* ``periodic( out.y, 100 ms )``: the gaps :mod:`.periods` measures: a late
  gap ``false``; at least two messages and no late gap ``true``; a single
  message and the run ending within the period ``inconclusive`` (too short
  to show a gap); none ``pending``.

Each row's status is its verdict's; the rows and their fold into the
node's record by the rule of evidence are :mod:`.declaration_evidence`'s
(:func:`declaration_status`, :func:`with_declarations`, re-exported here).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

from rclverify.semantics.floatsem import Tolerance, judge
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.walk import free_names, subexpressions
from rclverify.traces.events import Event
from rclverify.traces.mapping import MappingError, TopicRule, map_value, rule_for
from rclverify.backends.monitors.deadline_topics import topic_bindings
from rclverify.backends.monitors.periods import PeriodResult
from rclverify.backends.monitors.verdicts import LINK_TOPICS
from rclverify.backends.monitors.declaration_evidence import (STATUS, DeclarationResult, add_periods,
                                                              declaration_row, declaration_status, source_text,
                                                              with_declarations)

__all__ = ["STATUS", "DeclarationMonitor", "DeclarationResult", "add_periods", "call_part", "check_declarations",
           "declaration_status", "has_declarations", "with_declarations"]

#: a first value that did not map (a missing field, NaN): an ``initially`` on it is undecided
_UNMAPPED = object()
#: at most this many cached assumption verdicts (then the cache starts again)
_CACHE = 4096


@dataclass
class _Count:
    """One bounded-answer obligation (``progress`` or ``periodic`` in steps):
    ``bound`` K (``None``: eventually), ``outs`` the outputs that answer
    (empty: any output of the node); the row of unanswered accepted steps."""

    label: str
    source: str
    bound: int | None
    outs: frozenset[str]
    text: str
    premise: str = "progress"
    row: int = 0
    first_open: str = ""
    accepted: int = 0
    answered: int = 0
    broken: str = ""
    #: whether an answering output was heard yet: judging starts at the first one (its reader matched by then)
    heard: bool = False
    #: accepted steps before the first answering output was heard (not counted against the node)
    before: int = 0
    #: the longest row of unanswered accepted steps seen (counted from the first answering output)
    longest: int = 0
    #: the time (s) of the row's first step (its ``first_open``)
    first_open_t: float = 0.0
    #: the source times (s) of the answering outputs placed before their publication (``Event.source``)
    #: from the row's first step on: each may answer one step of the row
    maybe: list[float] = field(default_factory=list)
    #: why a row over the bound was not decided (the first such row), else ``""``
    undecided: str = ""


@dataclass
class _Initial:
    index: int
    formula: ast.Expr
    source: str
    outs: frozenset[str]
    verdict: str = ""
    reason: str = ""
    #: whether the run cannot show it: its first published value came after an input
    unobservable: bool = False


def has_declarations(node: CheckedNode) -> bool:
    """Whether ``node`` declares an initial value, progress or a period."""
    n = node.node
    return bool(n.initially or n.progress or n.periodic)


class DeclarationMonitor:
    """The declarations of ``node`` judged one event at a time (module
    docstring): :meth:`feed` every event of the run in order, then
    :meth:`finish` with the run's :class:`~.periods.PeriodResult` (or
    ``None`` when the node declares no period in time)."""

    def __init__(self, checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                 tolerance: Tolerance | None = None) -> None:
        from rclverify.backends.monitors.dds_calls import CALL_LOG_TOPIC  # deferred: start-up (loaded only by a run with a declaration)
        #: the topic of a live run's call lines (:data:`~.dds_calls.CALL_LOG_TOPIC`)
        self.call_topic = CALL_LOG_TOPIC
        self.checked, self.node, self.rules = checked, node, rules
        self.tolerance = tolerance if tolerance is not None else getattr(rules, "tolerance", None)
        #: inputs within the transport skew of a step's first, with no output between, are that step (skew.py)
        self.skew = getattr(rules, "skew", None) or 0.0
        self._step_at: float | None = None
        self._step_accepted = False
        self._step_topics: set[str] = set()
        self.bindings = topic_bindings(node)
        self.assumption = tuple(c.formula for c in node.node.assumes)
        self.needed = sorted(_inputs_read(self.assumption, node))
        self.needed_set = frozenset(self.needed)
        #: the assumption's verdict per tuple of the inputs it reads (a run repeats its inputs)
        self.accepted: dict[Any, bool] = {}
        #: the inputs the contract reads: an event carrying one of them is a step of the node
        self.read = frozenset(_inputs_read(self.assumption + tuple(c.formula for c in node.node.guarantees), node))
        #: input events the contract reads, accepted or not (a ``pending`` verdict says which it was)
        self.input_events = 0
        self.values: dict[str, object] = {}
        self.first: dict[str, tuple[Any, str]] = {}
        self.first_input = ""  # where the first input event was (an output message after it may be an answer)
        self.initials = [_Initial(k, c.formula, source_text(c.loc), frozenset(
            f"out.{e.name}" for e in subexpressions(c.formula) if isinstance(e, ast.Var) and e.prefix in ("out", None)
            and e.name in node.outputs)) for k, c in enumerate(node.node.initially, 1)]
        #: the outputs whose first value an ``initially`` reads and that were not published yet
        self.awaited = {o for ini in self.initials for o in ini.outs}
        self.counts: list[_Count] = []
        if node.node.progress or node.node.periodic:
            from rclverify.lang.liveness import _steps  # deferred: start-up (lang.timing and lang.liveness only for a node with progress or periodic)
        for p in node.node.progress:
            k = _steps(p.bound) if p.bound is not None else None
            self.counts.append(_Count("progress", source_text(p.loc), k, frozenset(),
                                      f"progress( {'eventually' if p.bound is None else f'within {p.bound} steps'} )"))
        for per in node.node.periodic:
            n = _steps(per.amount) if per.unit in ("steps", "step") else None
            if n:
                self.counts.append(_Count(f"periodic out.{per.output.name}", source_text(per.loc), n - 1,
                                          frozenset({f"out.{per.output.name}"}),
                                          f"periodic( out.{per.output.name}, {per.amount} {per.unit} )"))

    def feed(self, ev: Event) -> None:
        """Process one event (any topic; only the node's move its state).  A
        call line of a live run's log (:data:`~.dds_calls.CALL_LOG_TOPIC`:
        a request, response, goal, feedback or result of a link) is the
        event of its link's part, as the message on the link's topic is."""
        if ev.topic.strip("/") == self.call_topic:
            call = call_part(ev)
            if call is None:
                return
            ev, part_fields = call
        else:
            part_fields = None
        keys = self.bindings.get(ev.topic.lstrip("/"))
        if not keys:
            return
        changed = self._map(ev, keys, part_fields)
        outs = {c for c in changed if c.startswith("out.")}
        for key in outs:
            if key in self.awaited:
                self.awaited.discard(key)
                self.first[key] = (self.values.get(key, _UNMAPPED), ev.where)
                self._initial(ev)
        for c in self.counts:
            if outs and (not c.outs or c.outs & outs):
                if ev.source is not None and ev.source > ev.stamped:
                    c.maybe.append(ev.source)
                c.answered += 1 if c.row else 0
                c.row = 0
                c.heard = True
        if outs:
            self._step_at = None  # an output ends the instant: the next input is a step of its own
        if any(k in self.read for k in changed):
            self.input_events += 1
            self._step(ev)
        if not self.first_input and any(k.startswith("in.") for k in changed):
            self.first_input = ev.where

    def _map(self, ev: Event, keys: list[tuple[str, str]], part_fields: Mapping[str, Any] | None = None) -> list[str]:
        """The keys ``ev`` carries; the values mapped only where a judgement
        needs them (the assumption's inputs, an output whose first value an
        ``initially`` waits for): a step or an answer needs only the event.
        ``part_fields``: a call line's fields, the part's own."""
        changed = []
        for key, part in keys:
            fields = part_fields if part_fields is not None else ev.fields.get(part) if part else ev.fields
            typ = self.node.inputs.get(key[3:]) if key.startswith("in.") else self.node.outputs.get(key[4:])
            if not isinstance(fields, Mapping) or typ is None:  # an action message without this part
                continue
            changed.append(key)
            if key not in self.needed_set and key not in self.awaited:
                continue
            fields = {k: v for k, v in fields.items() if k != "header"}
            try:
                self.values[key] = map_value(typ, fields, rule_for(self.rules, ev.topic, key), self.values.get(key))
            except MappingError:
                self.values.pop(key, None)  # never the value before it: undecided until a message maps again
        return changed

    def _step(self, ev: Event) -> None:
        """An input event: the previous step ends (a row over its bound is
        broken), and a new step starts, accepted or not.  Inputs within the
        transport skew of the step's first input, with no output between,
        are one step (docs/semantics.md, "Steps"); before an answering output
        was first heard, an accepted step is counted apart (``before``)."""
        t = ev.stamped
        topic = ev.topic.strip("/")
        if self._step_at is not None and t - self._step_at < self.skew and topic not in self._step_topics:
            self._step_topics.add(topic)  # another input of the same instant (a topic not yet heard in it)
            if self._step_accepted or not self._accepts():
                return  # the same instant: one step
            self._step_accepted = True  # the step's inputs are now all there and accepted: counted once, below
            self._count_step(ev, True)
            return
        self._step_at, self._step_topics = t, {topic}
        self._step_accepted = accepted = self._accepts()
        self._end_rows(ev)
        self._count_step(ev, accepted)

    def _end_rows(self, ev: Event) -> None:
        for c in self.counts:
            if c.bound is None or c.row <= c.bound or c.broken:
                continue
            maybe = sum(c.first_open_t <= s <= ev.stamped for s in c.maybe)
            if c.row - maybe > c.bound:
                c.broken = (f"{c.row} accepted steps in a row unanswered (at most {c.bound} allowed): no "
                            f"{self._answer_words(c)} came between the input at {c.first_open} and the input at "
                            f"{ev.where}")
            elif not c.undecided:
                c.undecided = (f"{c.row} accepted steps in a row with no {self._answer_words(c)} placed among "
                               f"them (at most {c.bound} allowed), from the input at {c.first_open} to the input at "
                               f"{ev.where}, but {maybe} such message(s), placed before them at a stamp older than "
                               "their publication (a copied stamp, a clock standing still), were published among "
                               "them and may answer them (docs/semantics.md, \"Event time\")")

    def _count_step(self, ev: Event, accepted: bool) -> None:
        for c in self.counts:
            if accepted and not c.heard:
                c.accepted += 1
                c.before += 1
            elif accepted:
                c.accepted += 1
                if c.row == 0:
                    c.first_open, c.first_open_t = ev.where, ev.stamped
                    c.maybe = [s for s in c.maybe if s >= c.first_open_t]
                c.row += 1
                c.longest = max(c.longest, c.row)
            else:
                c.row = 0

    def _accepts(self) -> bool:
        """Whether the assumption holds of the current inputs (judged once per
        distinct tuple of the inputs it reads, kept while they repeat)."""
        if any(k not in self.values for k in self.needed):
            return False
        inputs = {k: self.values[k] for k in self.needed}
        try:
            key: Any = tuple(inputs.values())
            hash(key)
        except TypeError:  # a value that cannot be a key (a mutable one): judged every time
            key = None
        if key is not None and key in self.accepted:
            return bool(self.accepted[key])
        ok = all(judge(f, self.checked, self.node, inputs, self.tolerance).truth is True for f in self.assumption)
        if key is not None:
            if len(self.accepted) >= _CACHE:
                self.accepted.clear()
            self.accepted[key] = ok
        return ok

    def _answer_words(self, c: _Count) -> str:
        return "message of " + ", ".join(sorted(c.outs)) if c.outs else "output of the node"

    def _initial(self, ev: Event) -> None:
        for ini in self.initials:
            if ini.verdict or not all(o in self.first for o in ini.outs):
                continue
            unmapped = [o for o in sorted(ini.outs) if self.first[o][0] is _UNMAPPED]
            if unmapped:
                ini.verdict, ini.reason = "inconclusive", (
                    f"the first message of {unmapped[0]} ({self.first[unmapped[0]][1]}) does not map to a value")
                continue
            at = ", ".join(f"{o} = {self.first[o][0]!r} ({self.first[o][1]})" for o in sorted(ini.outs))
            if self.first_input:
                ini.unobservable = True
                ini.verdict, ini.reason = "inconclusive", (
                    f"the first published values ({at}) came after the input at {self.first_input}: they may be "
                    "the node's answer to it, not the value it starts from (a node publishes its initial value "
                    "when it starts, before its first input; or its implementation gives its initial outputs to "
                    "the property tests)")
                continue
            vals = {o: self.first[o][0] for o in ini.outs}
            j = judge(ini.formula, self.checked, self.node, vals, self.tolerance)
            if j.truth is True:
                ini.verdict, ini.reason = "true", f"the first published values satisfy it: {at}"
            elif j.truth is False:
                ini.verdict, ini.reason = "false", f"the first published values do not satisfy it: {at}"
            else:
                ini.verdict, ini.reason = "inconclusive", f"undecided on the first published values ({at}): {j.reason}"

    def finish(self) -> DeclarationResult:
        """The rows of every declaration after the run (module docstring)
        but the periods in time (:func:`add_periods`)."""
        res = DeclarationResult(self.node.name)
        for ini in self.initials:
            verdict, reason = (ini.verdict, ini.reason) if ini.verdict else (
                "pending", "no message of " + ", ".join(sorted(o for o in ini.outs if o not in self.first) or ["an output"])
                + ": its first value was not seen")
            res.declarations.append(declaration_row(f"initially {ini.index}", "initial value", ini.index, ini.source,
                                              f"initially( {expr_to_rcl(ini.formula)} )", verdict, reason))
            if ini.unobservable:
                res.unobservable.add(f"initially {ini.index}")
        for c in self.counts:
            row = declaration_row(c.label, c.premise, 0, c.source, c.text, *self._count_verdict(c))
            if row["verdict"] == "true" and c.bound is not None:
                row["spare"] = c.bound - c.longest  # the steps to spare (docs/semantics.md, "Margins in steps")
            res.declarations.append(row)
        return res

    def _count_verdict(self, c: _Count) -> tuple[str, str]:
        if c.broken:
            return "false", c.broken
        if c.undecided:
            return "inconclusive", c.undecided
        if not c.accepted and not self.input_events:
            return "pending", ("no input event of " + (", ".join(sorted(self.read)) or "the node")
                               + " was read (a message on its topics, or a call part in a live run's log): "
                               "nothing to answer")
        if not c.accepted:
            return "pending", (f"none of its {self.input_events} input event(s) meets its assumption: "
                               "nothing to answer")
        if not c.heard:
            return "inconclusive", (f"{c.accepted} accepted input event(s) came and no {self._answer_words(c)} was "
                                    "heard: judging starts at the first one (its reader may have matched after the "
                                    "inputs; a node that never answers is not green either)")
        before = (f"; {c.before} accepted input event(s) before the first {self._answer_words(c)} was heard were "
                  "not counted (its reader may have matched after them)") if c.before else ""
        if c.bound is None and c.row:
            return "inconclusive", (f"the run ends with the accepted input at {c.first_open} not answered yet "
                                    f"(a finite run never refutes 'eventually'){before}")
        return "true", (f"{c.accepted} accepted input events, none left unanswered for more than "
                        + (f"{c.bound} steps" if c.bound is not None else "the run") + before)


def _inputs_read(formulas: Iterable[ast.Expr], node: CheckedNode) -> set[str]:
    """``{"in.x"}``: the inputs of ``node`` that ``formulas`` read, a
    quantifier's domain included (``exists(r in in.ranges | ...)``), a name
    a quantifier binds not."""
    out: set[str] = set()
    for f in formulas:
        out |= {f"in.{v}" for v in free_names(f) if v in node.inputs}
        out |= {f"in.{e.name}" for e in subexpressions(f)
                if isinstance(e, ast.Var) and e.prefix == "in" and e.name in node.inputs}
    return out


#: the parts of a call line that carry a link's values (a goal's ``status`` carries none)
_CALL_PARTS = frozenset(p for parts in LINK_TOPICS.values() for p in parts)


def call_part(ev: Event) -> tuple[Event, Mapping[str, Any]] | None:
    """A live log's call line (``{"kind": "call", "link", "part", "fields"}``,
    :class:`~.dds_calls.CallBook`) as the event of its link's part on topic
    ``link/part``, with the part's fields; ``None`` for a line that carries
    no part (a status, a tick) or repeats a call for another server."""
    f = ev.fields
    part, link, fields = f.get("part"), f.get("link"), f.get("fields")
    if f.get("kind") != "call" or f.get("also") or part not in _CALL_PARTS or not isinstance(link, str) \
            or not isinstance(fields, Mapping):
        return None
    return Event(ev.index, ev.time, f"{link.strip('/')}/{part}", dict(fields), ev.where), fields


def check_declarations(checked: Checked, node: CheckedNode, events: Iterable[Event],
                       rules: Mapping[str, TopicRule], periods: PeriodResult | None = None) -> DeclarationResult:
    """The declarations of ``node`` over a recorded run's ``events``, in order."""
    m = DeclarationMonitor(checked, node, rules)
    for ev in events:
        m.feed(ev)
    return add_periods(m.finish(), node, periods)
