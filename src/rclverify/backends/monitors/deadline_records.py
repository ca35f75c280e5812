"""The records of the deadline monitor (:mod:`.deadlines`): one trigger's
verdict (:class:`DeadlineVerdict`) and one node's result on a run
(:class:`DeadlineResult`), with their JSON shapes (:mod:`.shapes`), and an
accepted trigger's open obligation (:class:`Pending`).

Verdicts in ROSMonitoring's terms (:data:`DEADLINE_VERDICTS`; docs/monitors.md):
``true`` answered in time, ``false`` the deadline expired or the answer came
late, ``currently_false`` not answered yet and the deadline not yet expired.
A trigger the node's assumption does not accept gets no verdict and is
counted by why (:data:`UNACCEPTED`); so is an obligation left unanswered whose
answer may be an output stamped within the transport skew before its trigger
(``undecided``, :attr:`Pending.maybe`), which is also given to the monitor's
``on_verdict`` as a :class:`DeadlineVerdict` ``undecided`` (not in the counts),
so that every trigger past its deadline has a verdict record on every path.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rclverify.traces.events import Event
from rclverify.backends.monitors.time_margins import TimeMargin, note

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import DeadlineResultJson, DeadlineVerdictJson, Unaccepted

DEADLINE_VERDICTS = ("true", "currently_false", "false")
#: Why a trigger got no deadline verdict (:attr:`DeadlineResult.unaccepted`): its assumption was false of
#: its inputs, an input had no value yet, or its assumption or (the transport skew) its answer undecided.
UNACCEPTED = ("assumption violated", "incomplete input", "undecided")


@dataclass(frozen=True)
class DeadlineVerdict:
    """One trigger event's deadline verdict: one of :data:`DEADLINE_VERDICTS`, or ``undecided`` (a
    trigger counted with the unaccepted ones: :mod:`.deadline_skew`).  Times in seconds on the stamps'
    clock; ``answer`` is the answering message's stamp (``None``: none)."""

    node: str
    guarantee: int
    verdict: str
    trigger_where: str
    trigger_stamp: float
    due: float
    answer: float | None = None
    answer_where: str = ""
    reason: str = ""
    #: the late answer of a trigger already judged ``false`` when its deadline expired (not a new verdict)
    update: bool = False
    #: the arithmetic the answer's formula held in (``exact``, ``double``, ``tolerance``; ``""``: no answer)
    semantics: str = ""
    #: the time margin (s): the deadline less the answer's stamp, exact in integer nanoseconds (negative: late;
    #: ``None``: no answer yet; docs/semantics.md, "Margins")
    time_margin: float | None = None

    def to_json(self) -> DeadlineVerdictJson:
        out: DeadlineVerdictJson = {
            "node": self.node, "guarantee": self.guarantee, "verdict": self.verdict,
            "trigger_where": self.trigger_where, "trigger_stamp": self.trigger_stamp, "due": self.due,
            "answer": self.answer, "answer_where": self.answer_where, "reason": self.reason,
            "update": self.update, "semantics": self.semantics}
        if self.time_margin is not None:
            out["time_margin"] = self.time_margin
        return out


@dataclass
class Pending:
    """One accepted trigger's open obligation: guarantee ``k`` (1-based), the
    trigger event, its stamp and deadline ``due`` (s), and the inputs it is judged on."""

    k: int
    trigger: Event
    stamp: float
    due: float
    inputs: dict[str, object]
    #: the outputs published after the trigger (stamp at or after it): only they answer it
    outs: dict[str, object] = field(default_factory=dict)
    #: the last output after the trigger that did not satisfy the guarantee (where, why)
    rejected: str = ""
    #: the trigger's stamp and its deadline in integer nanoseconds: what the deadline is compared in
    stamp_ns: int = 0
    due_ns: int = 0
    #: why an output stamped within the transport skew before the trigger may be its answer (it satisfies the
    #: guarantee on the trigger's inputs); ``""``: none is.  Unanswered by its deadline, such an obligation is
    #: ``undecided``, never ``false`` (docs/semantics.md, "Deadlines")
    maybe: str = ""
    #: the clock the deadline is kept in (:mod:`.deadline_clock`): ``""`` the run's clock, ``"sim"`` simulated
    #: time (``/clock``), ``"either"`` both, the node's clock not said
    clock: str = ""
    #: with a ``clock``: an answer stamped at or before it is in time in every clock the deadline may be kept
    #: in (``due_ns``: one after it is late in every such clock; between them ``undecided``), integer ns
    sure_ns: int = 0
    #: with a ``clock``: the deadline on the simulated clock, on the run's clock, and when (the run's clock)
    #: ``/clock`` passed the first (0: not yet), integer ns
    sim_due_ns: int = 0
    wall_due_ns: int = 0
    sim_passed_ns: int = 0
    #: with a ``clock``, answered before ``/clock`` passed its simulated deadline: the verdict given (``true``,
    #: or ``undecided`` in the band of a clock not said; ``""``: not so answered), the answer, its stamp
    #: (integer ns; also that of any answer whose margin is held, and of a late answer) and the arithmetic it
    #: held in; a ``/clock`` message heard later showing the deadline passed before that stamp judges it
    #: again (:func:`.deadline_clock.tick`)
    given: str = ""
    answer: Event | None = None
    answer_ns: int = 0
    semantics: str = ""
    #: the margin of an answer in a clock, noted withdrawable (:attr:`DeadlineResult.floor`'s shape) until
    #: ``/clock`` is heard after the answer or the answer leaves the window kept for a late ``/clock``
    held: tuple[int, int, str, str, float] | None = None
    #: held while no ``/clock`` had been heard, its node said to keep simulated time: no verdict is given until
    #: the first ``/clock`` message places it, or none came within the kept window (:func:`.deadline_first_clock.hold`)
    unclocked: bool = False
    #: held so (or, its node's clock not said, answered late on the run's clock before any ``/clock``: given
    #: again by the first one, :func:`.deadline_first_clock.unsaid_first`), the answer that came meanwhile: (the
    #: answer, its stamp in integer ns, the arithmetic it held in)
    first_answer: tuple[Event, int, str] | None = None
    #: what a verdict's reason adds on how it was placed (the first ``/clock`` heard late: ``""`` otherwise)
    placed: str = ""

    @property
    def bound_ns(self) -> int:
        """The guarantee's deadline (integer ns) this obligation is due after: its due time less its stamp on
        the run's clock, what a verdict's words call "the deadline of"."""
        return (self.wall_due_ns if self.clock else self.due_ns) - self.stamp_ns


#: an answer recorded for the first ``/clock`` message (:func:`.deadline_first_clock.record`), in plain values: the
#: guarantee, its margin noted withdrawable (:attr:`DeadlineResult.floor`'s shape), the trigger's stamp (ns),
#: stamp and due time (s), due time (ns), the trigger's index, time, topic and place, the answer's index,
#: time, topic and place, its stamp (ns), the arithmetic it held in, the verdict given (``true``, ``false``)
Recorded = tuple[int, tuple[int, int, str, str, float], int, float, float, int, int, float, str, str, int, float, str,
                 str, int, str, str]


@dataclass
class DeadlineResult:
    """Counts per verdict and the first ``false`` of one node on one run;
    ``unaccepted`` the (trigger, guarantee) pairs given no verdict, per reason
    (:data:`UNACCEPTED`), and the first of them (``first_unaccepted``:
    where, stamp, guarantee, reason)."""

    node: str
    counts: dict[str, int] = field(default_factory=lambda: {v: 0 for v in DEADLINE_VERDICTS})
    first_false: DeadlineVerdict | None = None
    unaccepted: dict[str, int] = field(default_factory=lambda: {v: 0 for v in UNACCEPTED})
    first_unaccepted: Unaccepted | None = None
    #: guarantee -> its smallest time margin on the run (:class:`TimeMargin`)
    time_margins: dict[int, TimeMargin] = field(default_factory=dict)
    #: guarantee -> the smallest margin among those no revision can withdraw (every one noted here but the
    #: late answers still held, :mod:`.deadline_late`): (margin ns, order noted, trigger, answer, answer s),
    #: the first of equals; what the smallest becomes when a held one is withdrawn
    floor: dict[int, tuple[int, int, str, str, float]] = field(default_factory=dict, repr=False)
    #: how many margins were noted (the order of each, :attr:`floor`)
    noted: int = field(default=0, repr=False)

    def to_json(self) -> DeadlineResultJson:
        return {"node": self.node, "counts": dict(self.counts),
                "first_false": None if self.first_false is None else self.first_false.to_json(),
                "unaccepted": dict(self.unaccepted), "first_unaccepted": self.first_unaccepted,
                "time_margins": [m.to_json() for _, m in sorted(self.time_margins.items())]}

    def note_time_margin(self, k: int, margin_ns: int | None, trigger_where: str, answer_where: str,
                         answer: float, was_unanswered: bool = False, held: bool = False) -> int:
        """Count guarantee ``k``'s time margin on one trigger (:func:`.time_margins.note`); ``held``: a
        late answer a revision may still withdraw (kept out of :attr:`floor` until :meth:`settle`).
        Returns the order it was noted in."""
        note(self.time_margins, k, margin_ns, trigger_where, answer_where, answer, was_unanswered)
        self.noted += 1
        if margin_ns is not None and not held:
            self.settle(k, (margin_ns, self.noted, trigger_where, answer_where, answer))
        return self.noted

    def settle(self, k: int, entry: tuple[int, int, str, str, float]) -> None:
        """Guarantee ``k``'s margin ``entry`` (:attr:`floor`'s shape) can no longer be withdrawn."""
        low = self.floor.get(k)
        if low is None or entry[:2] < low[:2]:
            self.floor[k] = entry

