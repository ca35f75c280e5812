"""The verdict engine: one node's contract judged on a stream of messages.

The stream model is docs/semantics.md's, asked of
:mod:`rclverify.traces.questions` (paper lines 462-495 for the contract,
1866-1869 for the one-in/one-out stream assumption, 791-980 for the
monitors).  Per node:

* a topic has no value until its first message, then its latest message;
* an input message raises a **question** (the inputs as they stand) once
  every input the contract reads has a value (before: ``incomplete
  input``); its assumption false: ``assumption violated`` (blamed on the
  producer), and the node owes it nothing; a question followed by another
  before any output is ``superseded`` (neither a failure nor inconclusive);
* **every output message is judged**: the guarantees that read an input
  against the question it answers (the latest at its stamp, and those
  within the transport skew after it, where both readings must agree), on
  the outputs published since that question (a topic the mapping declares a
  ``state`` with its current value); the guarantees over outputs only on
  the outputs as they stand.  False: ``violated`` (withdrawn only for a
  question heard late, :mod:`.late`); all true: ``satisfied``; undecided: ``inconclusive``.  A
  guarantee that reads an output not published since the question waits
  for it (a partial answer, judged when the horizon passes);
* a question whose owed guarantees its inputs alone decide is ``satisfied``
  (or ``violated``) at once; one with no output within the horizon is
  unanswered, ``inconclusive`` (a deadline, :mod:`.deadlines`, fails it);
  ``open`` when the run ends first.

:meth:`NodeMonitor.feed` takes one event, :meth:`NodeMonitor.advance` moves
the clock (a live monitor's timer), every verdict goes to ``on_verdict``
as it is decided.  An output message's judging is :mod:`.answering`'s;
inputs and questions are here.  Memory holds the values, the recent questions, the
outputs waiting for the skew to pass and a bounded evaluation cache.
"""
from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any, Callable, Mapping

from rclverify.semantics.floatsem import Judgement, Tolerance
from rclverify.semantics.judges import FormulaJudge
from rclverify.lang.types import Checked, CheckedNode
from rclverify.traces.events import Event
from rclverify.traces.mapping import MappingError, TopicRule, initial_value, rule_for, value_mapper
from rclverify.traces.questions import Question, QuestionStream
from rclverify.backends.monitors.answering import Answering
from rclverify.backends.monitors.run_origin import is_run_start
from rclverify.backends.monitors.needs_answer import answer_decides
from rclverify.backends.monitors.outcome import Outcome
from rclverify.backends.monitors.node_topics import node_topics
from rclverify.backends.monitors.verdicts import NodeResult, Verdict

if TYPE_CHECKING:
    from rclverify.backends.monitors.answered import Recent

_NO_RULE = TopicRule()  # the rule of a topic the mapping does not name
_NEVER = float("inf")
_NO_TRIGGERS: frozenset[str] = frozenset()
_SATISFIED = {sem: Outcome("satisfied", semantics=sem) for sem in ("exact", "double", "tolerance")}


class NodeMonitor(Answering):
    """Streams events through one node's contract; :meth:`finish` gives the result.

    ``rules`` maps topic names to :class:`TopicRule` (its ``tolerance`` and
    ``skew`` attributes, when it has them, as the mapping file's rules do,
    are the declared tolerance and the transport skew in seconds);
    ``horizon`` is in seconds; ``tolerance`` overrides the rules'.  Every
    formula is judged by :func:`rclverify.semantics.floatsem.judge` (exact,
    double, tolerance).  The node's topics are its ``topics(...)`` and the
    parts of its service and action links (:data:`~.verdicts.LINK_TOPICS`)."""

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
        self.topics, parts = node_topics(node)
        self.has_inputs = any(i for vs in self.topics.values() for _, _, i in vs)
        self._feeds = {topic: [(key, value_mapper(typ, rule_for(rules, topic, key, _NO_RULE)), parts.get((topic, key), ""))
                               for key, typ, _ in vs] for topic, vs in self.topics.items()}
        self._topic_io = {topic: (frozenset(k for k, _, inp in vs if inp), [k for k, _, inp in vs if not inp])
                          for topic, vs in self.topics.items()}
        self.values: dict[str, object] = {}
        #: variables whose latest message did not map (NaN, infinity, a missing field): key -> why
        self.invalid: dict[str, str] = {}
        for topic, vs in self.topics.items():
            for key, typ, _ in vs:
                self.values[key] = initial_value(typ, rule_for(rules, topic, key, _NO_RULE))
        self._read_contract(node)
        self._sort_guarantees(rules)
        self._start_stream(rules, horizon)
        self._make_judges(checked, node)

    def _start_stream(self, rules: Mapping[str, TopicRule], horizon: float) -> None:
        """The questions' stream and what the engine remembers of the run."""
        skew = getattr(rules, "skew", None) or 0.0
        self.stream = QuestionStream(skew if self.has_inputs else 0.0, horizon)
        #: outputs judged at once, for a question within the skew after them that gets no answer of its own
        self._recent: deque[Recent] = deque(maxlen=64)
        #: outputs false for the question at their stamp, waiting for the questions within the skew after them:
        #: (event, stamp, that question, outputs of the answer, state outputs, output-only outcome, its reading)
        self._held: deque[tuple[Any, ...]] = deque()
        #: with margins: each held output's message margin (event index -> margin), for its verdict
        self._held_margins: dict[int, float | None] = {}
        #: outputs held for the skew and judged since, kept as ``_recent`` keeps those judged at once (late.py)
        self._released: deque[Recent] = deque(maxlen=64)
        self._given: deque[tuple[int, str, str]] = deque(maxlen=256)  # (event, verdict, semantics): late.py
        #: the outputs counted ``unasked`` (no question at their stamp when judged), the last 64: an input heard
        #: late and stamped before one makes it an answer, judged then (late.py, ``_answers_late``)
        self._unasked: deque[int] = deque(maxlen=64)
        #: event index -> how far after its stamp (s) a question may be the one an output answers, where that is
        #: beyond the skew: published that long after its stamp (a stamp copied from an earlier question)
        self._wins: dict[int, float] = {}
        #: input -> the message heard later than the lateness bound whose value is in force (``Event.late``),
        #: and question event index -> that message, for the questions that read it: what they decide is
        #: undecided, never violated (closing.py ``_violation``)
        self._late_in: dict[str, Event] = {}
        self._late_q: dict[int, Event] = {}
        #: input -> (stamp, why) of its latest unreadable message (a NaN) until a message stamped after it maps
        self._unread: dict[str, tuple[float, str]] = {}
        #: the latest stamp (s) of the node's messages judged so far: an input stamped before it was heard late
        self._hi = float("-inf")
        #: whether an output of the node was heard yet: a question closed unanswered before it is not counted
        #: (its readers may have matched after it: docs/semantics.md, "Steps")
        self.heard_answer = False
        #: before the first question: input -> the (stamp, value, event) of the messages that set it (the last 64)
        self._in_force: dict[str, list[tuple[float, Any, Event]]] = {}
        #: the one question whose horizon is watched: the latest owed one (an earlier one was followed by a
        #: newer question within its horizon, which owes what it lacks, or was closed when its horizon passed)
        self._open: Question | None = None
        self._due = _NEVER
        #: the questions (their event index, the last 1024) given ``superseded`` before every writer of the
        #: node's outputs had been heard past them (:attr:`answers_heard_past`): an answer its stamp pairs with
        #: one withdraws that verdict (late.py ``_answers_superseded``)
        self._early_superseded: dict[int, None] = {}

    def _make_judges(self, checked: Checked, node: CheckedNode) -> None:
        """One compiled judge per formula, the evaluation cache, and whether a
        question's guarantees are evaluated when it comes."""
        self._cache: dict[tuple[Any, tuple[Any, ...]], Judgement] = {}
        self._assumed = [(("A", j), f) for j, f in enumerate(self.assumption)]
        self._guaranteed = dict(enumerate(self.guarantees, 1))
        self._judges = {k: FormulaJudge(f, checked, node, self.tolerance)
                        for k, f in self._assumed + list(self._guaranteed.items())}
        self.result.evaluation = {(f"assumption {k[1] + 1}" if isinstance(k, tuple) else f"guarantee {k}"):
                                  (j.fallback or "compiled") for k, j in self._judges.items()}
        # a question's guarantees evaluated when it comes, unless Z3 showed that only an answer decides them
        self._ask_at_question = any(not self._reads_out[k] for k in self._asked) or not (
            self.has_inputs and not self._state_outs and not self._trigger
            and answer_decides(checked, node, self.guarantees))

    def _verdict(self, verdict: str, ev: Event, guarantee: int = 0, values: Mapping[str, str] | None = None,
                 reason: str = "", semantics: str = "", question: str = "", provisional: bool = False) -> None:
        self.result.counts[verdict] += 1
        self._given.append((ev.index, verdict, semantics))
        if verdict == "satisfied" and semantics in self.result.semantics:
            self.result.semantics[semantics] += 1
        if verdict == "inconclusive" and self.result.first_inconclusive is None:
            self.result.first_inconclusive = {"event": ev.index, "time": ev.time, "where": ev.where,
                                              "reason": reason}
        if self.on_verdict is not None:
            self.on_verdict(Verdict(self.node.name, verdict, ev.index, ev.time, ev.where, ev.topic,
                                    max(self.now, ev.time), guarantee, dict(values or {}), reason, semantics,
                                    question, self._message_margin(ev, verdict), provisional))

    # -- streaming ---------------------------------------------------------------
    def feed(self, ev: Event) -> None:
        """Process one event: every event moves the clock (releasing outputs
        past the skew, closing questions past their horizon); only events on
        the node's topics change its state.  A message's outputs are judged
        before its inputs raise a question (an answer comes after its question)."""
        t = ev.time
        if t > self.now:
            self.now = t
        if self._held and self.now > self._held[0][1] + self._reach_of(self._held[0][0]):
            self._release(self.now)
        if self.now > self._due:
            self._expire(self.now)
        vs = self._feeds.get(ev.topic)
        if vs is None:
            if is_run_start(ev.topic, ev.fields):
                self.first.start()
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
                # the value in force is stale now: a gate holds back what reads it (dds_enforce.py)
                self.invalid[key] = why = f"the latest message at {ev.where} does not map ({exc})"
                trig = self._topic_io[ev.topic][0]
                if key in trig and self.has_inputs and values.get(key) is not None:
                    # the input changed to a value that does not map: the question before it is superseded by an
                    # undecided one (its verdict says why), so no later answer is judged on the value before the
                    # NaN (docs/semantics.md, "Values")
                    self._input(ev, trig)
                else:
                    self._verdict("inconclusive", ev, reason=f"{key}: {exc}")
                self.invalid[key] = why
                self._unread[key] = (ev.stamped, why)  # a message heard late does not clear it (late.py)
                if ev.stamped > self._hi:
                    self._hi = ev.stamped
                return
            if self.invalid:
                self.invalid.pop(key, None)
        trig, changed = self._topic_io[ev.topic]
        if trig and self.first.keys:
            self.first.mark(trig, values)
        if changed:
            self.heard_answer = True
            self._output(ev, changed)
        if trig:
            self._input(ev, trig)

    def advance(self, now: float) -> None:
        """Move the clock to ``now`` (s): outputs past the skew are judged,
        questions past their horizon closed.  A time before the clock is ignored."""
        if now > self.now:
            self.now = now
        if self._held:
            self._release(self.now)
        self._expire(self.now)

    @property
    def pending(self) -> bool:
        """Whether a question still waits for its answer (owed, unanswered or
        partly answered, within its horizon) or an output for the skew to pass."""
        q = self._open
        return bool(self._held) or (q is not None and bool(q.waiting or not (q.answered or q.settled or q.reported)))

    def _state(self) -> dict[str, object]:
        values = self.values
        return {k: values[k] for k in self._state_outs if values[k] is not None}

    def _input(self, ev: Event, trig: frozenset[str]) -> None:
        stamp = ev.time if ev.stamp is None else ev.stamp
        if stamp < self._hi:  # heard after a message stamped later: its place is found by its stamp (late.py)
            self._late_input(ev, trig, stamp)
            return
        self._hi = stamp
        if ev.late or self._late_in:  # a message later than the bound: the questions reading its value
            for k in trig:
                if ev.late:
                    self._late_in[k] = ev
                else:
                    self._late_in.pop(k, None)
        if self._unread:  # a message stamped after the unreadable one: readable values are in force again
            for k in trig:
                self._unread.pop(k, None)
        values = self.values
        inputs = {k: values[k] for k in self._in_keys if values[k] is not None}
        if len(inputs) < len(self._in_keys):
            missing = [k for k in self.needed_inputs if k not in inputs]
            if missing:  # not a question yet: nothing before the first message
                for k in trig:  # before the first question, what a message heard late finds in force (late.py)
                    kept = self._in_force.setdefault(k, [])
                    kept.append((stamp, values[k], ev))
                    if len(kept) > 64:
                        del kept[0]
                self._verdict("incomplete input", ev, reason="no value yet for " + ", ".join(missing))
                return
        owed, accepted, refusal = self._accept(ev, inputs)
        if self._late_in:  # a question asked before a message later than the bound was heard: its own
            for k, cause in list(self._late_in.items()):
                if stamp < cause.stamped + cause.late:
                    self._late_asked(ev, cause)
                    break
                del self._late_in[k]  # heard by then: the node had it
        self._raise(ev, Question(ev, stamp, inputs, owed, accepted), trig, refusal)

    def _raise(self, ev: Event, q: Question, trig: frozenset[str], refusal: str) -> None:
        """Question ``q``, raised by ``ev`` (its message set the inputs ``trig``), is the latest:
        it supersedes the one before it (docs/semantics.md) and is watched for its horizon."""
        owed = q.owed
        old = self.stream.ask(q, trig & self._triggers if self._triggers else _NO_TRIGGERS)
        if self._open is not None and self._open.followed:  # it owes nothing more: the new question does
            followed, self._open, self._due = self._open, None, _NEVER
            if followed.waiting:
                self._wrong_whatever(followed)
        if old is not None:
            old.reported = True
            if (self.stream.skew or self._wins) and self._recent:
                self._early_answer(old)
            # a writer of its answers not heard past it yet: provisional, withdrawn if its answer comes (late.py)
            self._verdict("superseded", old.event, reason=f"the input at {ev.where} came before any output "
                          f"answered the question raised at {old.event.where}: the node owes the latest one an answer",
                          provisional=self._superseded_early(old.event, old.event.time))
        if refusal:
            self._verdict("inconclusive", ev, reason=refusal)
        if not owed:
            return
        self.result.accepted += 1
        if self._unowed(q):
            return
        q.due = ev.time + self.horizon
        self._open, self._due = q, q.due
        if self._ask_at_question:
            self._at_question(q)

    def _unowed(self, q: Question) -> bool:
        """Whether every guarantee of the node is ``triggered by`` an input ``q`` does not carry: nothing
        is owed to ``q`` (counted ``unowed``, settled: no verdict of its own, never ``superseded``).  The
        rule of a question raised in order and of one placed at its stamp, heard late (late.py)."""
        if self._trigger and self._asked and not self._alone and not any(self._owes(q, k) for k in self._asked):
            self.result.unowed += 1
            q.settled = True
            return True
        return False

    def _expire(self, now: float) -> None:
        """Close the watched question when its horizon passed before ``now``."""
        q = self._open
        if q is not None and q.due < now and not self._at_due(now, q.due):
            self._open, self._due = None, _NEVER
            if q.answered and not q.waiting and (q.followed or q.decided.issuperset(self._need)):
                q.reported = True  # answered in full: nothing to say (the common case, inline)
                return
            self._close(q)

    def finish(self) -> NodeResult:
        """Close the run: held outputs are judged, questions past their horizon
        closed, the rest ``open``."""
        if self._held:
            self._release(self.now, end=True)
        q = self._open
        if q is not None:  # every output judged: a question past its horizon is closed, else open
            self._open = None
            self._close(q, end=not (self.now > q.due and not self._at_due(self.now, q.due)))
        self._due = _NEVER
        return self.result


__all__ = ["NodeMonitor"]
