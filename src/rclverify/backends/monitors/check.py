"""Offline checking of one node's contract on a recorded trace.

Semantics (docs/monitors.md; paper lines 462-495 for the contract, 791-980
for the monitors): the node's state is the latest value of each input and
output, mapped from the messages on its topics (:mod:`rclverify.traces.mapping`).
Every message on an input topic is an *input event*:

* once every input the contract mentions has been observed, the assumption
  is evaluated on the inputs: false -> the event's verdict is
  ``assumption violated`` (blamed on the environment or on the upstream
  node producing the input); true -> the event opens an obligation on the
  inputs as they are now;
* **an answer comes after its question** (docs/monitors.md): the guarantees
  are evaluated on the obligation's inputs and the outputs published after
  the event (later in the trace, stamped at or after it), at once and again
  at every later output message; all true -> ``satisfied``.  An output
  current before the event answered an earlier one and is no answer, unless
  the mapping declares its topic a ``state`` (then its current value stands
  in).  An obligation whose answer has not come on an output a guarantee
  needs waits for it;
* an obligation not satisfied within ``horizon`` seconds of its event is
  ``violated`` (``inconclusive`` when its last evaluation could not be
  decided).  The violating event reported is the last output event that
  failed the obligation before the node's next input event (the node's
  answer to it), with the guarantee that failed there, or "no output"
  when none came.  When the node's next input event came before any output
  answered the event, and only the outputs after it failed, the verdict is
  ``inconclusive``: those outputs answer the inputs as they stood then;
* at the end of the trace, obligations still within their horizon are
  ``open``.

A node with no input topics checks its guarantees on every output event.
A variable not observed yet has no value (never ``None`` passed to the
formulas): an obligation whose guarantees need an output not yet seen waits
for it ("no output" when none comes within the horizon).

This is one engine for recorded and live runs: :meth:`NodeMonitor.feed`
takes one event, :meth:`NodeMonitor.advance` moves the clock without an
event (a live monitor's timer), and every input event's verdict is passed,
as soon as it is decided, to the ``on_verdict`` callback as a
:class:`Verdict`.  :func:`check_trace` is that engine run over a recorded
trace.  Memory holds only the state, the evaluation cache (bounded) and the
pending obligations (grouped by equal inputs, those within the horizon),
never the trace.
"""
from __future__ import annotations

import dataclasses
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping

from ...logic.floatsem import Judgement, Tolerance, judge
from ...logic.judges import FormulaJudge
from ...rcl import ast
from ...rcl.printer import expr_to_rcl
from ...rcl.types import Checked, CheckedNode
from ...system.services import peers
from ...traces.events import Event
from ...traces.mapping import MappingError, TopicRule, initial_value, value_mapper
from ...values import render
from .needs_answer import answer_decides
from .skew import EarlyOutputs, early_reason

VERDICTS = ("satisfied", "violated", "open", "assumption violated", "inconclusive", "incomplete input")
#: Topic suffixes of a service's or action's parts, in the order of ``Link.parts``
#: (a service ``s`` is observed as ``s/request`` and ``s/response`` events, an
#: action ``a`` as actionlib's ``a/goal``, ``a/feedback`` and ``a/result``).
LINK_TOPICS = {"service": ("request", "response"), "action": ("goal", "feedback", "result")}
#: How far a semantics is from exact arithmetic (the weakest one a verdict rests on is shown).
_WEAK = {"exact": 0, "double": 1, "tolerance": 2}
_NO_RULE = TopicRule()  # the rule of a topic the mapping does not name
_NEVER = float("inf")
_NO_TRIGGERS: frozenset[str] = frozenset()


def _reads(e: Any, out: set[str]) -> None:
    """Every name a formula mentions: each :class:`ast.Var`'s qualified and bare
    name, anywhere in the tree (quantifier domains included); a superset of
    the I/O variables it reads."""
    if isinstance(e, ast.Var):
        out.add(e.qualified)
        out.add(e.name)
        return
    if isinstance(e, tuple):
        for x in e:
            _reads(x, out)
        return
    if dataclasses.is_dataclass(e) and not isinstance(e, (type, ast.Loc)):
        for f in dataclasses.fields(e):
            _reads(getattr(e, f.name), out)


def _names(e: Any, out: set[str]) -> None:
    if isinstance(e, ast.Var):
        out.add(e.qualified)
    for name in ("args", "operand", "left", "right", "operands", "elem", "collection", "items", "body", "func"):
        c = getattr(e, name, None)
        if c is None:
            continue
        for x in (c if isinstance(c, tuple) else (c,)):
            _names(x, out)


@dataclass(frozen=True)
class Verdict:
    """The verdict of one event of one node, as soon as it is decided.

    ``verdict`` one of :data:`VERDICTS`; ``event``/``time``/``where``/``topic``
    identify the input event it is about (for a node without inputs, the
    output event); ``guarantee`` the 1-based guarantee that failed (0 when
    none or for the assumption); ``decided_at`` the time (s, trace clock)
    when it was decided; ``values`` the rendered values of the first failure
    (inputs and the outputs that failed), ``reason`` one sentence;
    ``semantics`` the arithmetic that decided it (:mod:`rclverify.logic.floatsem`):
    ``exact``, ``double`` or ``tolerance`` for a ``satisfied`` (the weakest
    its assumption and guarantees needed), the semantics that all agreed for
    a ``violated`` or ``assumption violated`` (``exact, double``), else ``""``.
    """

    node: str
    verdict: str
    event: int
    time: float
    where: str
    topic: str
    decided_at: float
    guarantee: int = 0
    values: Mapping[str, str] = field(default_factory=dict)
    reason: str = ""
    semantics: str = ""

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (the live monitor's verdict message)."""
        return {"node": self.node, "verdict": self.verdict, "event": self.event, "time": self.time,
                "where": self.where, "topic": self.topic, "decided_at": self.decided_at,
                "guarantee": self.guarantee, "values": dict(self.values), "reason": self.reason,
                "semantics": self.semantics}


@dataclass(slots=True)
class _Group:
    """Pending input events with equal inputs and equal answers so far: their
    events, the event outputs published since them (``outs``: only those may
    answer), the latest event's time (``ref``: an output stamped before it is
    no answer), deadlines and last outcome."""

    inputs: dict[str, Any]
    events: deque[Event] = field(default_factory=deque)
    last: tuple[Event, int, dict[str, Any]] | None = None  # (output event, failing guarantee, outputs)
    undecided: str = ""
    answered: bool = False  # a later input event arrived: the node's answer to these events is complete
    outs: dict[str, Any] = field(default_factory=dict)
    ref: float = float("-inf")
    ikey: tuple[Any, ...] = ()
    #: the next input event came before any output answered these events: the
    #: outputs after it answer the inputs as they stood then
    superseded: Event | None = None
    #: a partial answer: (output event, guarantee, why it waits, the outputs that came)
    waiting: tuple[Event, int, str, dict[str, Any]] | None = None
    #: the semantics the inputs' assumption held in, and those that agreed on ``last``'s failure
    accepted: str = "exact"
    last_semantics: str = ""
    #: the inputs the events set (``in.x``): a guarantee ``triggered by`` another input is no answer to them
    triggers: frozenset[str] = frozenset()


@dataclass
class NodeResult:
    """Verdicts of one node on one trace.

    ``counts`` verdict -> number of input events; ``first_violation`` and
    ``first_assumption_violation`` are dicts (event index, time, where,
    guarantee, formula, values, reason) or ``None``; ``events`` is the
    number of events on the node's topics; ``accepted`` the input events
    whose assumption held; ``semantics`` the ``satisfied`` verdicts per the
    arithmetic that decided them (``exact``, ``double``, ``tolerance``);
    ``first_inexact`` the first formula that held only in double arithmetic
    or within the tolerance (event, where, time, semantics, formula, values);
    ``unowed`` the input events that met the assumption and that no
    guarantee answers (each is ``triggered by`` another input): no verdict,
    nothing was checked for them.
    ``evaluation`` how each formula was evaluated (debug; not in :meth:`to_json`).
    """

    node: str
    counts: dict[str, int] = field(default_factory=lambda: {v: 0 for v in VERDICTS})
    events: int = 0
    first_violation: dict[str, Any] | None = None
    first_assumption_violation: dict[str, Any] | None = None
    first_inconclusive: dict[str, Any] | None = None
    accepted: int = 0
    semantics: dict[str, int] = field(default_factory=lambda: {"exact": 0, "double": 0, "tolerance": 0})
    first_inexact: dict[str, Any] | None = None
    unowed: int = 0
    #: a debug field, in no evidence record: how each formula was evaluated
    #: (``assumption 1`` / ``guarantee 2`` -> ``compiled``, or why the
    #: straight-line code left it to the evaluator; logic/judges.py)
    evaluation: dict[str, str] = field(default_factory=dict, compare=False)

    @property
    def assumption(self) -> dict[str, Any]:
        """The assumption monitor's verdict on the run: ``violated`` when an
        input event violated it (the node is not at fault: the blame names the
        producer), ``held`` when every evaluated input event met it, ``not
        evaluated`` when none was evaluated."""
        n = self.counts["assumption violated"]
        verdict = "violated" if n else "held" if self.accepted else "not evaluated"
        return {"verdict": verdict, "violations": n, "accepted": self.accepted,
                "first": self.first_assumption_violation}

    def to_json(self) -> dict[str, Any]:
        return {"node": self.node, "counts": dict(self.counts), "events": self.events,
                "first_violation": self.first_violation,
                "first_assumption_violation": self.first_assumption_violation,
                "first_inconclusive": self.first_inconclusive, "accepted": self.accepted,
                "semantics": dict(self.semantics), "first_inexact": self.first_inexact, "unowed": self.unowed}


def producers(checked: Checked, node: CheckedNode, var: str) -> list[str]:
    """Other nodes whose output has the input's name or is matched to the
    input's topic, or feeds it through a service or action link (rule S1,
    :func:`rclverify.system.services.peers`: a client's response comes from
    the server, a server's request from its clients)."""
    topics = {t.field for t in node.node.topics if t.match is not None and t.match.name == var}
    out = {m for m, _ in peers(checked, node.name, var)} if node.node.links else set()
    for other in checked.nodes.values():
        if other.name == node.name:
            continue
        if var in other.outputs or any(t.field in topics and t.match is not None and t.match.name in other.outputs
                                       for t in other.node.topics):
            out.add(other.name)
    return sorted(out)


def link_of(node: CheckedNode, var: str) -> str:
    """``service estop`` when input ``var`` of ``node`` is a part of a service
    or action link (its response, feedback, result, or a server's request),
    else ``""``."""
    for lk in node.node.links:
        if any(v.prefix == "in" and v.name == var for v in lk.parts):
            return f"{lk.kind} {lk.name}"
    return ""


class NodeMonitor:
    """Streams events through one node's contract; :meth:`finish` gives the result.

    ``rules`` maps topic names to :class:`TopicRule`; ``horizon`` is in
    seconds; ``tolerance`` the declared tolerance of recorded numbers
    (:class:`~rclverify.logic.floatsem.Tolerance`; default: the ``tolerance``
    attribute of ``rules`` when it has one, as the mapping file's rules do,
    else none).  Every formula is judged by
    :func:`rclverify.logic.floatsem.judge` (exact, double, tolerance).  The
    node's topics are its ``topics(...)`` and the parts of its service and
    action links (:data:`LINK_TOPICS`; an action's part is the message's
    ``goal``/``feedback``/``result`` field).
    """

    #: Evaluations remembered per (formula, inputs, outputs); 0 turns the cache off.
    cache_size = 4096

    def __init__(self, checked: Checked, node: CheckedNode, rules: Mapping[str, TopicRule],
                 horizon: float, on_verdict: Callable[[Verdict], None] | None = None,
                 tolerance: Tolerance | None = None) -> None:
        self.checked, self.node, self.horizon = checked, node, horizon
        self.rules = rules
        self.tolerance = tolerance if tolerance is not None else getattr(rules, "tolerance", None)
        self.on_verdict = on_verdict
        self.now = float("-inf")
        self.result = NodeResult(node.name)
        self.topics: dict[str, list[tuple[str, Any, bool]]] = {}
        for t in node.node.topics:
            if t.match is None:
                continue
            typ = node.io_type(t.match)
            if typ is None:
                continue
            is_input = t.match.prefix == "in" or (t.match.prefix is None and t.match.name in node.inputs)
            key = ("in." if is_input else "out.") + t.match.name
            self.topics.setdefault(t.field.lstrip("/"), []).append((key, typ, is_input))
        #: (topic, key) -> the part of an actionlib message that maps to the variable
        self._parts: dict[tuple[str, str], str] = {}
        for lk in node.node.links:
            for suffix, v in zip(LINK_TOPICS.get(lk.kind, ()), lk.parts):
                typ = node.io_type(v)
                if typ is None or v.prefix not in ("in", "out"):
                    continue
                topic, key = f"{lk.name.lstrip('/')}/{suffix}", f"{v.prefix}.{v.name}"
                self.topics.setdefault(topic, []).append((key, typ, v.prefix == "in"))
                if lk.kind == "action":
                    self._parts[(topic, key)] = suffix
        self.has_inputs = any(i for vs in self.topics.values() for _, _, i in vs)
        #: per topic, what its message sets, made once: (variable, its mapper, actionlib part)
        self._feeds = {topic: [(key, value_mapper(typ, rules.get(topic, _NO_RULE)),
                                self._parts.get((topic, key), "")) for key, typ, _ in vs]
                       for topic, vs in self.topics.items()}
        #: per topic, the inputs it sets (the triggers of its events) and the outputs, made once
        self._topic_io = {topic: (frozenset(k for k, _, inp in vs if inp), [k for k, _, inp in vs if not inp])
                          for topic, vs in self.topics.items()}
        self.values: dict[str, Any] = {}
        for topic, vs in self.topics.items():
            for key, typ, _ in vs:
                self.values[key] = initial_value(typ, rules.get(topic, TopicRule()))
        self.assumption = tuple(c.formula for c in node.node.assumes)
        self.guarantees = tuple(c.formula for c in node.node.guarantees)
        #: guarantee k -> ``in.x`` for ``triggered by in.x``: it answers the events of that input only
        self._trigger = {k: f"in.{c.trigger.name}" for k, c in enumerate(node.node.guarantees, 1)
                         if c.trigger is not None}
        self._triggers = frozenset(self._trigger.values())
        self._texts = {k: expr_to_rcl(f) for k, f in enumerate(self.guarantees, 1)}  # printed once, not per verdict
        self._renders: dict[int, tuple[Any, str]] = {}
        needed: set[str] = set()
        for f in self.assumption + self.guarantees:
            _names(f, needed)
        self.needed_inputs = sorted(k for k in self.values if k.startswith("in.") and
                                    (k in needed or k[3:] in needed))
        #: variables the contract reads that no topic or link part carries: no run gives them a value
        self.unbound = sorted(f"{p}.{v}" for p, names in (("in", node.inputs), ("out", node.outputs))
                              for v in names if f"{p}.{v}" not in self.values and (v in needed or f"{p}.{v}" in needed))
        self._outputs = sorted(k for k in self.values if k.startswith("out."))
        # outputs whose every topic the mapping declares a state: their current
        # value may stand in for an answer; any other output answers only the
        # input events before it (docs/monitors.md, "An answer comes after its
        # question").  A node without inputs checks its outputs as they stand.
        event_outs = {key for topic, vs in self.topics.items() for key, _, inp in vs
                      if not inp and not rules.get(topic, TopicRule()).state}
        self._state_outs = [k for k in self._outputs if k not in event_outs or not self.has_inputs]
        self._state_set = frozenset(self._state_outs)
        self._keys = {p: [k for k in self.values if k.startswith(p)] for p in ("in.", "out.")}  # in state order
        # the dependency index: each formula's truth is a function of the I/O
        # variables it mentions, so its cached evaluations are keyed on those
        # values only (a guarantee that does not read `at` is not evaluated
        # again when only `at` changed)
        self._deps: dict[Any, tuple[str, ...]] = {}
        for k, f in [(("A", j), f) for j, f in enumerate(self.assumption)] + list(enumerate(self.guarantees, 1)):
            mentioned: set[str] = set()
            _reads(f, mentioned)
            self._deps[k] = tuple(v for v in sorted(self.values) if v in mentioned or v.split(".", 1)[1] in mentioned)
        self.pending: dict[Any, _Group] = {}
        skew = getattr(rules, "skew", None)
        #: the outputs of the last ``skew`` seconds: an answer received just before its question (skew.py)
        self._early = EarlyOutputs(skew) if skew and self.has_inputs else None
        self._due = float("inf")  # the earliest horizon among the pending obligations (s)
        self._cache: dict[tuple[Any, tuple[Any, ...]], Judgement] = {}
        # each formula compiled once (logic/judges.py): straight-line code decides what it can, judge() the rest
        self._assumed = [(("A", j), f) for j, f in enumerate(self.assumption)]
        self._guaranteed = list(enumerate(self.guarantees, 1))
        self._judges = {k: FormulaJudge(f, checked, node, self.tolerance) for k, f in self._assumed + self._guaranteed}
        self.result.evaluation = {(f"assumption {k[1] + 1}" if isinstance(k, tuple) else f"guarantee {k}"):
                                  (j.fallback or "compiled") for k, j in self._judges.items()}
        self._in_keys = self._keys["in."]
        # a question's guarantees evaluated when it comes, unless Z3 showed that only an answer decides them
        # (needs_answer.py: a speed fact; the value mappers refuse a NaN or infinite REAL, Z3's reals have none)
        self._ask_at_question = not (self.has_inputs and not self._state_outs and not self._trigger
                                     and answer_decides(checked, node, self.guarantees))

    # -- evaluation --------------------------------------------------------------
    def _judge(self, k: Any, formula: ast.Expr, values: Mapping[str, Any]) -> Judgement:
        """The judgement of guarantee ``k`` (``("A", j)``: assumption ``j``) on
        ``values`` (:func:`~rclverify.logic.floatsem.judge`: exact, then the
        node's double arithmetic, then the tolerance).  The formula's compiled
        judge answers first where it can alone (:class:`FormulaJudge`); what
        it leaves to ``judge`` is remembered per (formula, values of the
        variables it reads)."""
        hit = self._judges[k].quick(values)
        if hit is not None:
            return hit
        ck = (k, tuple([values.get(d) for d in self._deps[k]]))
        hit = self._cache.get(ck)
        if hit is not None:
            return hit
        j = judge(formula, self.checked, self.node, values, self.tolerance)
        if self.cache_size:
            if len(self._cache) >= self.cache_size:
                self._cache.clear()
            self._cache[ck] = j
        return j


    def _rendered(self, values: Mapping[str, Any]) -> dict[str, str]:
        return {k: self._render(v) for k, v in sorted(values.items()) if v is not None}

    def _render(self, v: Any) -> str:
        """``render(v)``, remembered per value object (a table is rendered once
        while it stays the state, not at every verdict that shows it)."""
        hit = self._renders.get(id(v))
        if hit is not None and hit[0] is v:
            return hit[1]
        if len(self._renders) >= 256:
            self._renders.clear()
        text = render(v)
        self._renders[id(v)] = (v, text)
        return text

    def _verdict(self, verdict: str, ev: Event, guarantee: int = 0, values: Mapping[str, str] | None = None,
                 reason: str = "", n: int = 1, semantics: str = "") -> None:
        self.result.counts[verdict] += n
        if verdict == "satisfied" and semantics in self.result.semantics:
            self.result.semantics[semantics] += n
        if self.on_verdict is not None:
            v = Verdict(self.node.name, verdict, ev.index, ev.time, ev.where, ev.topic, max(self.now, ev.time),
                        guarantee, dict(values or {}), reason, semantics)
            for _ in range(n):
                self.on_verdict(v)

    # -- streaming ---------------------------------------------------------------
    def feed(self, ev: Event) -> None:
        """Process one event: every event moves the clock (closing obligations
        past their horizon); only events on the node's topics change its state.
        An event's outputs answer the obligations opened before it, then its
        inputs open a new one (an answer comes after its question)."""
        t = ev.time  # the clock first (advance(), inline: this runs for every event)
        if t > self.now:
            self.now = t
        if self.pending and self.now > self._due:
            self._expire(self.now)
        vs = self._feeds.get(ev.topic)
        if vs is None:
            return
        self.result.events += 1
        values = self.values
        for key, mapper, part in vs:
            fields: Any = ev.fields
            try:
                if part:
                    fields = fields.get(part)
                    if not isinstance(fields, Mapping):
                        raise MappingError(f"the actionlib message has no {part!r} part")
                values[key] = mapper(fields, values.get(key))
            except MappingError as exc:
                self._note_inconclusive(ev, 0, f"{key}: {exc}")
                return
        trig, changed = self._topic_io[ev.topic]  # every variable of the topic was set: made once, not per event
        if changed:
            self._output(ev, changed)
        if trig or (changed and not self.has_inputs):
            self._input(ev, trig)

    def _state(self) -> dict[str, Any]:
        """The outputs on state topics as they stand (observed ones only)."""
        values = self.values
        return {k: values[k] for k in self._state_outs if values[k] is not None}

    def _input(self, ev: Event, trig: frozenset[str] = frozenset()) -> None:
        for g in self.pending.values():
            g.answered = True
            if not g.outs and g.superseded is None:
                g.superseded = ev
        values = self.values
        inputs = {k: values[k] for k in self._in_keys if values[k] is not None}
        if len(inputs) < len(self._in_keys):
            missing = [k for k in self.needed_inputs if k not in inputs]
            if missing:
                self._verdict("incomplete input", ev, reason="no value yet for " + ", ".join(missing))
                return
        accepted = "exact"
        judges = self._judges
        for aj, formula in self._assumed:
            judged = judges[aj].quick(inputs) or self._judge(aj, formula, inputs)  # the compiled code first
            ok, reason = judged.truth, judged.reason
            if ok is False:
                mentioned: set[str] = set()
                _names(formula, mentioned)
                reads = [k for k in inputs if k in mentioned or k[3:] in mentioned]
                blamed = sorted({p for k in reads for p in producers(self.checked, self.node, k[3:])})
                links = sorted({link_of(self.node, k[3:]) for k in reads} - {""})
                blame = ("upstream node(s) " + ", ".join(blamed)) if blamed else "environment"
                if blamed and links:
                    blame += f" (through {', '.join(links)})"
                if self.result.first_assumption_violation is None:
                    self.result.first_assumption_violation = {
                        "event": ev.index, "time": ev.time, "where": ev.where, "assumption": expr_to_rcl(formula),
                        "values": self._rendered(inputs), "blame": blame, "semantics": judged.semantics}
                self._verdict("assumption violated", ev, values=self._rendered(inputs),
                              reason=f"assumption {expr_to_rcl(formula)} is false; blamed on the {blame}",
                              semantics=judged.semantics)
                return
            if ok is None:
                self._note_inconclusive(ev, 0, f"assumption undecided: {reason}")
                return
            if judged.semantics != "exact" and _WEAK.get(judged.semantics, 0) > _WEAK[accepted]:
                accepted = judged.semantics
                self._note_inexact(ev, judged, f"assumption {expr_to_rcl(formula)}", inputs)
        self.result.accepted += 1
        if self._triggers and all(k in self._trigger and self._trigger[k] not in trig
                                  for k in range(1, len(self.guarantees) + 1)):
            self.result.unowed += 1  # every guarantee answers another input: nothing is owed to this event
            return
        # the question: the inputs, and which triggers of the node's guarantees this event set (a node
        # without triggered guarantees groups its events by their inputs alone, as before)
        trig = trig & self._triggers if self._triggers else _NO_TRIGGERS
        ikey = (tuple(inputs.items()), trig)
        key = (ikey, ())  # no answer yet: only a group that has none either is the same obligation
        group = self.pending.get(key)
        if group is None:
            group = self.pending[key] = _Group(inputs, ikey=ikey, accepted=accepted, triggers=trig)
        elif _WEAK[accepted] > _WEAK[group.accepted]:
            group.accepted = accepted
        group.events.append(ev)
        stamped = ev.time if ev.stamp is None else ev.stamp  # ev.stamped, inline: this runs for every input
        if stamped > group.ref:
            group.ref = stamped
        group.superseded = None  # the same question asked again: the answer to come answers both
        due = ev.time + self.horizon
        if due < self._due:
            self._due = due
        if len(group.events) == 1 and self._ask_at_question:
            done: list[Any] = []
            self._evaluate(key, group, ev, self._state() if self._state_outs else {}, done)
            for k in done:
                del self.pending[k]
            if not self.pending:
                self._due = _NEVER  # no obligation left: no horizon to watch

    def _output(self, ev: Event, changed: list[str]) -> None:
        """Outputs ``changed`` were just set by ``ev``: they answer every pending
        obligation whose question is not stamped after ``ev``; a state output's
        new value is seen by every obligation."""
        values = self.values
        states = self._state_set
        if states:
            fresh = {k: values[k] for k in changed if k not in states and values[k] is not None}
            state_changed = any(k in states for k in changed)
            state = self._state()
        else:
            fresh = {k: values[k] for k in changed if values[k] is not None}
            state_changed, state = False, {}
        if fresh and self._early is not None:
            self._early.remember((ev, fresh))
        done: list[Any] = []
        rekey = False
        stamped = ev.time if ev.stamp is None else ev.stamp  # ev.stamped, inline
        has_fresh = bool(fresh)
        for key, g in self.pending.items():
            answered = has_fresh and stamped >= g.ref
            if answered:
                g.outs.update(fresh)
                rekey = True
            if answered or state_changed:
                self._evaluate(key, g, ev, state, done)
        for key in done:
            del self.pending[key]
        if not self.pending:
            self._due = _NEVER  # no obligation left: no horizon to watch
        elif rekey:
            self._rekey()

    def _evaluate(self, key: Any, g: _Group, ev: Event, state: Mapping[str, Any], done: list[Any]) -> None:
        """Evaluate group ``g``'s guarantees on its inputs, the state outputs and
        the outputs that answered it; satisfied -> verdicts and ``key`` in ``done``."""
        if state or g.outs:
            values = dict(g.inputs)
            values.update(state)
            values.update(g.outs)
        else:  # only read below: no copy needed
            values = g.inputs
        failed: int | None = None
        undecided = ""
        weakest = g.accepted
        inexact: list[tuple[int, Judgement]] = []
        failed_semantics = ""
        judges, trigger = self._judges, self._trigger
        for k, formula in self._guaranteed:
            if trigger and k in trigger and trigger[k] not in g.triggers:
                continue  # triggered by another input: no answer to these events is owed (docs/monitors.md)
            judged = judges[k].quick(values) or self._judge(k, formula, values)  # the compiled code first
            ok, reason = judged.truth, judged.reason
            if ok is False:
                failed, failed_semantics = k, judged.semantics
                break
            if ok and judged.semantics != "exact":
                inexact.append((k, judged))
                if _WEAK.get(judged.semantics, 0) > _WEAK[weakest]:
                    weakest = judged.semantics
            if ok is None:
                if reason.startswith("no value for out."):  # no answer on that output yet: wait for it
                    if g.outs and g.last is None:  # a partial answer: shown if nothing completes it
                        g.waiting = (ev, k, reason, dict(g.outs))
                    return
                undecided = f"guarantee {k}: {reason}" + self._unbound_note(reason)
                break
        if failed is None and not undecided:
            for k, judged in inexact[:1]:
                self._note_inexact(g.events[0], judged, f"guarantee {k} ({self._texts[k]})", values)
            for trigger in g.events:
                self._verdict("satisfied", trigger, semantics=weakest)
            done.append(key)
        elif failed is not None and (g.last is None or not g.answered):
            g.last, g.undecided = (ev, failed, {k: v for k, v in values.items() if k.startswith("out.")}), ""
            g.last_semantics = failed_semantics
        else:
            g.undecided = undecided

    def _unbound_note(self, reason: str) -> str:
        """A note for an undecided ``reason`` that waits on a variable no topic
        carries (a contract whose ``topics(...)`` leave an input out): no run
        will ever give it a value."""
        names = [v for v in self.unbound if f"no value for {v}" in reason]
        if not names:
            return ""
        return (f" ({', '.join(names)} of {self.node.name} is carried by no topic or link part: its topics(...) "
                "and services(...)/actions(...) name none, so no run gives it a value)")

    def _rekey(self) -> None:
        """Regroup the pending obligations by (inputs, answers so far): two groups
        that now hold equal inputs and equal answers are one obligation from here on."""
        merged: dict[Any, _Group] = {}
        for g in self.pending.values():
            key = (g.ikey, tuple(sorted(g.outs.items())))
            h = merged.get(key)
            if h is None:
                merged[key] = g
                continue
            h.events = deque(sorted([*h.events, *g.events], key=lambda e: (e.time, e.index)))
            h.ref = max(h.ref, g.ref)
            h.last = h.last or g.last
            h.waiting = h.waiting or g.waiting
            h.undecided = h.undecided or g.undecided
            h.answered = h.answered and g.answered
            h.superseded = h.superseded if g.superseded is not None else None
            if _WEAK[g.accepted] > _WEAK[h.accepted]:
                h.accepted = g.accepted
            if h.last is g.last:  # h took g's failure: and the semantics it was decided in
                h.last_semantics = g.last_semantics
        self.pending = merged

    def advance(self, now: float) -> None:
        """Move the monitor's clock to ``now`` (s): obligations whose horizon has
        passed are closed (``violated`` or ``inconclusive``).  A live monitor
        calls it from a timer, so a missing answer is reported without waiting
        for the next message.  A time before the clock is ignored."""
        if now > self.now:
            self.now = now
        self._expire(self.now)

    def _expire(self, now: float) -> None:
        if not self.pending or now <= self._due:
            return  # no obligation's horizon has passed yet
        empty = []
        for key, g in self.pending.items():
            while g.events and g.events[0].time + self.horizon < now:
                self._close(g, g.events.popleft())
            if not g.events:
                empty.append(key)
        for key in empty:
            del self.pending[key]
        self._due = min((g.events[0].time + self.horizon for g in self.pending.values()), default=float("inf"))

    def _close(self, g: _Group, trigger: Event) -> None:
        if g.undecided and g.last is None:
            self._first_inconclusive(trigger, g.undecided)
            self._verdict("inconclusive", trigger, reason=g.undecided)
            return
        if g.last is not None and g.superseded is not None and g.last[0].index > g.superseded.index:
            reason = (f"the next input event ({g.superseded.where}) came before any output answered the input at "
                      f"{trigger.where}; the outputs after it (guarantee {g.last[1]} false at {g.last[0].where}) "
                      f"answer the inputs as they stood then, so this event's own answer cannot be told apart")
            self._first_inconclusive(trigger, reason)
            self._verdict("inconclusive", trigger, guarantee=g.last[1], reason=reason)
            return
        first: dict[str, Any]

        def on_answer(out: Event, k: int, outputs: Mapping[str, Any], reason: str, semantics: str = "") -> dict[str, Any]:
            return {"event": out.index, "time": out.time, "where": out.where, "guarantee": k,
                    "formula": self._texts[k], "trigger": trigger.index, "trigger_time": trigger.time,
                    "trigger_where": trigger.where, "values": self._rendered({**g.inputs, **outputs}),
                    "reason": reason, **({"semantics": semantics} if semantics else {})}
        if g.last is None and g.waiting is not None:
            out, k, why, outs = g.waiting
            if not self._false_whatever_missing(k, {**g.inputs, **outs}):
                # a partial answer (some outputs published after the input, another never): the guarantee cannot
                # be judged, which is not the same as false. An output that keeps its value without being published
                # again (a latched topic) is declared `state: true` in the mapping (docs/monitors.md)
                missing = why.split(" ", 3)[-1].split(",")[0] if why.startswith("no value for ") else why
                reason = (f"guarantee {k} is undecided on the outputs published after the input at {trigger.where} "
                          f"(the last at {out.where}): {why}; nothing published within {self.horizon} s completed "
                          f"the answer (if {missing} keeps its value between messages, declare its topic "
                          "`state: true` in the mapping)")
                self._first_inconclusive(trigger, reason)
                self._verdict("inconclusive", trigger, guarantee=k, values=self._rendered({**g.inputs, **outs}),
                              reason=reason)
                return
            # no value of the missing outputs could make it hold: false on what was answered
            first = on_answer(out, k, outs, f"guarantee {k} is false on the outputs published after the input at "
                              f"{trigger.where} (the last at {out.where}) whatever the value of the outputs not "
                              f"published after it ({why})")
        elif g.last is None and self._early is not None and (early := self._early.before(trigger.stamped)):
            out, outs = early
            k, semantics = self._early_failure(g, outs)
            reason = early_reason(k, out, trigger, self._early.skew, self.horizon)
            if k is None:  # the early output meets the guarantees: an answer or a stale output, not told apart
                self._first_inconclusive(trigger, reason)
                self._verdict("inconclusive", trigger, values=self._rendered({**g.inputs, **outs}), reason=reason)
                return
            first = on_answer(out, k, outs, reason, semantics)
        elif g.last is None:
            first = {
                "event": trigger.index, "time": trigger.time, "where": trigger.where, "guarantee": None,
                "formula": "", "values": self._rendered(g.inputs),
                "reason": f"no output satisfying the guarantees within {self.horizon} s of the input event"}
        else:
            out, k, outputs = g.last
            first = on_answer(out, k, outputs, f"guarantee {k} is false on the output at {out.where} answering the "
                              f"input at {trigger.where}{_in_all(g.last_semantics)}, and no output within "
                              f"{self.horizon} s satisfied it", g.last_semantics)
            first.setdefault("semantics", g.last_semantics)
        if self.result.first_violation is None:
            self.result.first_violation = first
        self._verdict("violated", trigger, guarantee=first["guarantee"] or 0, values=first["values"],
                      reason=first["reason"], semantics=first.get("semantics", ""))

    def _early_failure(self, g: _Group, outs: Mapping[str, Any]) -> tuple[int | None, str]:
        """The first guarantee owed to ``g`` that is false on its inputs, the
        state outputs and the early outputs ``outs``, with the semantics that
        agreed, or ``(None, "")`` when none is (all hold, or one is undecided)."""
        values = {**g.inputs, **self._state(), **outs}
        for k, formula in self._guaranteed:
            if k in self._trigger and self._trigger[k] not in g.triggers:
                continue
            judged = self._judge(k, formula, values)
            if judged.truth is False:
                return k, judged.semantics
        return None, ""

    def _false_whatever_missing(self, k: int, values: Mapping[str, Any]) -> bool:
        """Is guarantee ``k`` false on ``values`` (a partial answer) whatever the
        outputs missing from it are (Z3, :func:`~...logic.concrete.false_whatever_the_rest`)?"""
        import z3

        from ...logic.concrete import false_whatever_the_rest
        known = {q: v for q, v in values.items() if v is not None}
        try:
            return false_whatever_the_rest(self.guarantees[k - 1], self.checked, self.node, known)
        except (KeyError, ValueError, z3.Z3Exception):
            return False  # cannot be shown false: the partial answer stays undecided

    def _note_inexact(self, ev: Event, judged: Judgement, what: str, values: Mapping[str, Any]) -> None:
        """Remember the first formula that held only in double arithmetic or
        within the tolerance (the evidence names the semantics that decided)."""
        if self.result.first_inexact is None:
            self.result.first_inexact = {"event": ev.index, "time": ev.time, "where": ev.where,
                                         "semantics": judged.semantics, "formula": what,
                                         "values": self._rendered(values), "reason": judged.reason}

    def _note_inconclusive(self, ev: Event, k: int, reason: str) -> None:
        self._first_inconclusive(ev, reason)
        self._verdict("inconclusive", ev, guarantee=k, reason=reason)

    def _first_inconclusive(self, ev: Event, reason: str) -> None:
        if self.result.first_inconclusive is None:
            self.result.first_inconclusive = {"event": ev.index, "time": ev.time, "where": ev.where,
                                              "reason": reason}

    def finish(self) -> NodeResult:
        """Close the run: obligations past their horizon are violated, the rest open."""
        for g in self.pending.values():
            why = f" ({g.undecided})" if g.undecided else ""
            if g.undecided and g.events:  # why it waited: named in the evidence (backend.verdict_status)
                self._first_inconclusive(g.events[0], f"unanswered when the run ended: {g.undecided}")
            for trigger in g.events:
                self._verdict("open", trigger, reason=f"unanswered when the run ended, within {self.horizon} s{why}")
        self.pending.clear()
        return self.result


def _in_all(semantics: str) -> str:
    """`` (false in exact and double arithmetic)`` for a failure that every
    float semantics agreed on, ``""`` when only exact arithmetic applied."""
    names = [s for s in semantics.split(", ") if s]
    if len(names) < 2:
        return ""
    words = {"exact": "exact", "double": "double", "tolerance": "within the tolerance"}
    said = [words.get(n, n) for n in names]
    arith = [w for w in said if w in ("exact", "double")]
    text = " and ".join(arith) + " arithmetic" + (" and " + said[-1] if "within the tolerance" in said else "")
    return f" (false in {text})"


def check_trace(checked: Checked, nodes: Iterable[CheckedNode], events: Iterable[Event],
                rules: Mapping[str, TopicRule], horizon: float,
                on_verdict: Callable[[Verdict], None] | None = None,
                tolerance: Tolerance | None = None,
                end: float | None = None) -> tuple[int, list[NodeResult]]:
    """Stream ``events`` through a monitor per node; returns (events read, results).

    The online engine (:class:`NodeMonitor`) run over a recorded trace: each
    event is fed in order, the clock advanced to the last event's time at the
    end (or to ``end``, seconds, when the run is known to have gone on after
    its last event: a live run's log, whose monitor kept its clock), then
    every monitor finished.  ``on_verdict`` receives every event's verdict
    as it is decided; ``tolerance`` as for :class:`NodeMonitor`.  Raises
    whatever the event source raises (:class:`TraceError`) after the events
    before it were processed.
    """
    monitors = [NodeMonitor(checked, n, rules, horizon, on_verdict, tolerance) for n in nodes]
    count = 0
    last_time = 0.0
    if len(monitors) == 1:  # feed() moves the clock first itself
        feed = monitors[0].feed
        for ev in events:
            count += 1
            last_time = ev.time
            feed(ev)
    else:
        for ev in events:
            count += 1
            last_time = ev.time
            for m in monitors:  # every clock first (as a live monitor's timer would), then the message
                m.advance(ev.time)
            for m in monitors:
                m.feed(ev)
    for m in monitors:
        m.advance(max(last_time, end) if end is not None else last_time)
    return count, [m.finish() for m in monitors]


__all__ = ["LINK_TOPICS", "VERDICTS", "NodeMonitor", "NodeResult", "Verdict", "check_trace", "link_of", "producers"]
