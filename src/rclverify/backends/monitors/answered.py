"""The questions of a run of answer pairs the batch path judged (backends/monitors/batch.py).

After a run of pairs the stream of :mod:`rclverify.traces.questions` keeps the
last 64 to 128 questions, each answered by its pair's output; the engine looks
one up only for an event stamped before the latest question.  The batch path
makes the newest at once and the others, from this record, only then: the
fields are those the engine sets on a question answered by one output that
decided every guarantee (``answered``, ``answer``, ``view``, ``decided``,
``due``; a ``triggered by`` node's ``triggers`` and ``answered_triggers``, its
trigger; ``followed`` when the next question came within its horizon, else
``reported``: it was closed, answered in full, when its horizon passed).

:class:`RecentOutput` is likewise one of the 64 answers the engine remembers
for the transport skew (``NodeMonitor._recent``), its event made only if
the engine reads it (a question left unanswered, ``closing.py``).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping, Union

from rclverify.core.numeric import np

from rclverify.traces.events import Event
from rclverify.traces.questions import Question

if TYPE_CHECKING:
    from rclverify.backends.monitors.rows import BlockRows, EventRows


class AnsweredRun:
    """A run of answer pairs judged in batch, whose questions are made when asked for.

    ``at`` the pairs' input positions in ``chunk``; ``where`` per input key the
    position of the message that set it (< 0: ``seed``, its value before the run).
    :meth:`question` takes the batch run (``run.m`` the engine, ``run.plan`` its
    plan, ``run.fields`` each input key's field)."""

    __slots__ = ("chunk", "at", "where", "seed", "carried")

    def __init__(self, chunk: EventRows | BlockRows, at: np.ndarray, where: dict[str, np.ndarray],
                 seed: dict[str, object], carried: Mapping[str, Event] | None = None) -> None:
        self.chunk, self.at, self.where, self.seed = chunk, at, where, seed
        #: ``triggered by``: the triggers the first question took from the one before it (the earliest message each)
        self.carried = carried or {}

    def question(self, j: int, run: Any) -> Question:
        """The ``j``-th pair's question as the engine leaves it once answered (questions.py's fields)."""
        chunk, plan, h = self.chunk, run.plan, run.m.horizon
        i = int(self.at[j])
        qe, ev = chunk[i], chunk[i + 1]
        inputs = {}
        mapped = plan.mapped  # a window's value is its mapper's; any other the message's field itself
        for k in run.m._in_keys:  # (value_mapper's one-field rule)
            w = int(self.where[k][j])
            inputs[k] = (mapped[k](chunk[w].fields) if k in mapped else chunk[w].fields[run.fields[k]]) \
                if w >= 0 else self.seed[k]
        q = Question(qe, qe.time, inputs, True, "exact")
        q.answered = True
        q.last_out = ev
        okey = plan.output[1]
        mine = {okey: mapped[okey](ev.fields) if okey in mapped else ev.fields[plan.output[2]]}
        q.answer = mine
        view = dict(inputs)
        view.update(mine)
        q.view = view
        q.due = qe.time + h
        if plan.triggers:  # its own trigger (or the one carried to it), answered by its output: carried no further
            own = next(k for k in run.m._in_keys if int(self.where[k][j]) == i)  # the input its message set
            q.decided = {k for k in plan.asked if plan.triggers.get(k, own) == own}  # the guarantees it owes
            if own in plan.triggers.values():
                q.triggers = {own: self.carried.get(own, qe) if j == 0 else qe}
                q.mark("answered_triggers", own)
        else:
            q.decided = set(plan.asked)
        if j + 1 < len(self.at):  # the next question of the run followed it within its horizon, or it expired first
            if chunk[int(self.at[j + 1])].time <= qe.time + h:
                q.followed = True
            else:
                q.reported = True
        return q


class RecentOutput:
    """An entry of the engine's ``_recent`` outputs, ``(event, stamp, {key: value}, {})``
    as ``engine.py`` appends it, for the answer at row ``i`` of a batch chunk
    (``rows[i]`` its event, made when an item other than the stamp is read);
    ``stamp`` its time (s), ``key``/``field`` the output's variable and field, ``mapped`` its value from
    the message's fields where that is not the field itself (a window).
    Compared by identity, as the engine's own entries (each a distinct event)."""

    __slots__ = ("rows", "i", "stamp", "key", "field", "mapped")

    def __init__(self, rows: EventRows | BlockRows, i: int, stamp: float, key: str, field: str,
                 mapped: Callable[[Mapping[str, object]], Any] | None = None) -> None:
        self.rows, self.i, self.stamp, self.key, self.field = rows, i, stamp, key, field
        self.mapped = mapped

    def __getitem__(self, k: int) -> Any:
        return self.stamp if k == 1 else self._entry()[k]

    def __iter__(self) -> Iterator[Any]:
        return iter(self._entry())

    def __len__(self) -> int:
        return 4

    def _entry(self) -> tuple[Event, float, dict[str, object], dict[str, object]]:
        ev = self.rows[self.i]
        value = ev.fields[self.field] if self.mapped is None else self.mapped(ev.fields)
        return ev, self.stamp, {self.key: value}, _EMPTY


_EMPTY: dict[str, object] = {}

#: An entry of the engine's ``_recent`` (and ``_released``) outputs: the tuple
#: ``engine.py`` appends, or a :class:`RecentOutput` of a batch run.
Recent = Union[tuple[Event, float, dict[str, object], Mapping[str, object]], RecentOutput]

__all__ = ["AnsweredRun", "Recent", "RecentOutput"]
