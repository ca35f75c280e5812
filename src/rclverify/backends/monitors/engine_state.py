"""The state of :class:`~.engine.NodeMonitor` that its parts share, as types.

The engine is split by job over :mod:`.judging`, :mod:`.closing` and
:mod:`.late` (each a mixin of :class:`~.engine.NodeMonitor`); each part
reads the engine's state and calls the others' helpers.  :class:`EngineState`
is their typed base: the attributes :class:`~.engine.NodeMonitor` sets (in
its ``__init__`` and the methods it calls there) and, for the type checker
only, the helpers one part calls of another, with their signatures.  It
holds no value and no behaviour of its own.
"""
from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any, Callable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.floatsem import Judgement, Tolerance
from rclverify.semantics.judges import FormulaJudge
from rclverify.traces.event_time import STALE_S
from rclverify.traces.events import Event
from rclverify.traces.questions import Question, QuestionStream
from rclverify.backends.monitors.verdicts import NodeResult, Verdict

if TYPE_CHECKING:
    from rclverify.backends.monitors.answered import Recent
    from rclverify.backends.monitors.outcome import Outcome


class EngineState:
    """The engine's state its parts read (module docstring); set by :class:`~.engine.NodeMonitor`."""

    # the contract and the run (engine.py ``__init__``, ``_read_contract``)
    checked: Checked
    node: CheckedNode
    horizon: float
    now: float
    tolerance: Tolerance | None
    result: NodeResult
    on_verdict: Callable[[Verdict], None] | None
    values: dict[str, object]
    invalid: dict[str, str]
    assumption: tuple[ast.Expr, ...]
    guarantees: tuple[ast.Expr, ...]
    needed_inputs: list[str]
    unbound: list[str]
    cache_size: int
    _topic_io: dict[str, tuple[frozenset[str], list[str]]]
    _trigger: dict[int, str]
    _triggers: frozenset[str]
    _texts: dict[int, str]
    _renders: dict[int, tuple[Any, str]]
    # which formula reads what (``_sort_guarantees``)
    _deps: dict[Any, tuple[str, ...]]
    _asked: list[int]
    _need: list[int]
    _reads_out: dict[int, bool]
    _state_outs: list[str]
    _touch: dict[str, tuple[list[int], list[int]]]
    # the questions' stream and what the engine remembers of the run (``_start_stream``)
    stream: QuestionStream
    heard_answer: bool
    _recent: deque[Recent]
    _held: deque[tuple[Any, ...]]
    _released: deque[Recent]
    _given: deque[tuple[int, str, str]]
    _unasked: deque[int]
    _wins: dict[int, float]
    _late_in: dict[str, Event]
    _late_q: dict[int, Event]
    _unread: dict[str, tuple[float, str]]
    _in_force: dict[str, list[tuple[float, Any, Event]]]
    _open: Question | None
    _due: float
    _lost: set[int]
    _early_superseded: dict[int, None]
    # the judges (``_make_judges``)
    _cache: dict[tuple[Any, tuple[Any, ...]], Judgement]
    _assumed: list[tuple[tuple[str, int], ast.Expr]]
    _guaranteed: dict[int, ast.Expr]
    _judges: dict[Any, FormulaJudge]

    def _reach(self, ev: Event, stamped: float) -> float:
        """How far after its stamp ``stamped`` (s) a question may be the one output
        ``ev`` answers: the transport skew, or, for an output published more than
        :data:`~rclverify.traces.event_time.STALE_S` after its stamp (its source
        time: ``ev.source``, or its trace time where ``ev.stamp`` is its header
        stamp), up to then: a node that copied an earlier question's stamp onto
        its answer answers a question asked before it published
        (docs/semantics.md, "Event time").  Noted for :meth:`_reach_of`."""
        src = ev.source if ev.source is not None else ev.time if ev.stamp is not None else stamped
        lag = src - stamped
        if lag > STALE_S and lag > self.stream.skew:
            wins = self._wins
            if len(wins) >= 1024:
                del wins[next(iter(wins))]  # the oldest: long judged
            wins[ev.index] = lag
            return lag
        return self.stream.skew

    def _late_asked(self, q_ev: Event, cause: Event) -> None:
        """The question raised by ``q_ev`` reads the value of ``cause``, a message heard
        later than the lateness bound: a violation found on it is ``inconclusive``
        (closing.py ``_violation``; the last 1024 such questions are kept)."""
        late = self._late_q
        if len(late) >= 1024:
            del late[next(iter(late))]
        late[q_ev.index] = cause

    def _reach_of(self, ev: Event) -> float:
        """:meth:`_reach` of an output already judged or held."""
        return self._wins.get(ev.index, self.stream.skew)

    def _stale_reason(self, ev: Event, q: Question | None, others: list[Question]) -> str:
        """The sentence of an output published well after its stamp whose readings
        disagree: the question at its stamp (``q``) or one of ``others``, asked
        before it was published."""
        first = f"the question at {q.event.where}" if q is not None else "no question (none was asked before it)"
        asked = ", ".join(o.event.where for o in others)
        return (f"the output at {ev.where} was published {self._wins[ev.index] * 1e3:.1f} ms after its header "
                f"stamp, after the question(s) at {asked}: it answers {first} (its stamp) or one of them (a stamp "
                "copied from an earlier question), and the readings give different verdicts, which the run cannot "
                "tell apart (docs/semantics.md, \"Event time\")")

    def _within(self, ev: Event) -> str:
        """The words for the questions output ``ev`` may answer: within the skew, or
        until it was published (its stamp older than that)."""
        reach = self._wins.get(ev.index)
        if reach is None:
            return f"within the transport skew of {self.stream.skew:g} s"
        return (f"until it was published, {reach * 1e3:.1f} ms after its stamp (a header stamp older than the "
                "message: copied from an earlier question?)")

    if TYPE_CHECKING:  # the helpers one part calls of another (defined in engine.py and the parts)
        def _verdict(self, verdict: str, ev: Event, guarantee: int = 0, values: Mapping[str, str] | None = None,
                     reason: str = "", semantics: str = "", question: str = "", provisional: bool = False) -> None: ...

        def _state(self) -> dict[str, object]: ...

        def _raise(self, ev: Event, q: Question, trig: frozenset[str], refusal: str) -> None: ...

        def _judge(self, k: Any, values: Mapping[str, object]) -> Judgement: ...

        def _rendered(self, values: Mapping[str, object]) -> dict[str, str]: ...

        def _note_inexact(self, ev: Event, judged: Judgement, what: str, values: Mapping[str, object]) -> None: ...

        def _owes(self, q: Question, k: int) -> bool: ...

        def _unowed(self, q: Question) -> bool: ...

        def _question_outcome(self, q: Question | None, ev: Event, ks: list[int], outs: Mapping[str, object],
                              state: Mapping[str, object], keep: bool = True) -> Outcome: ...

        def _accept(self, ev: Event, inputs: dict[str, object]) -> tuple[bool, str, str]: ...

        def _violation(self, ev: Event, k: int, values: Mapping[str, object], reason: str, semantics: str,
                       trigger: Event | None) -> None: ...

        def _unbound_note(self, reason: str) -> str: ...

        def _at_due(self, t: float, due: float) -> bool: ...


__all__ = ["EngineState"]
