"""The engine's state after a clean chunk of lone triggers and answers (:mod:`.batch_lone`): the margins
counted in the engine's order, the questions the stream keeps, the watched one and the input's value, as
feeding the chunk event by event leaves them (questions.py ``ask``: a trigger no answer answered is
carried to the next question; docs/semantics.md, "Questions")."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.core.numeric import np

from rclverify.traces.events import Event
from rclverify.traces.questions import Question, kept_after
from rclverify.backends.monitors.verdicts import KEPT_MARGINS

if TYPE_CHECKING:
    from rclverify.backends.monitors.batch_plan import BatchPlan
    from rclverify.backends.monitors.engine import NodeMonitor
    from rclverify.backends.monitors.rows import BlockRows, EventRows


class LoneState:
    """The part of the lone slots' judge (:class:`~.batch_lone.LoneSlots`) that sets the engine's state;
    ``m`` the engine, ``plan`` its batch plan, ``fields`` each input key's message field."""

    m: NodeMonitor
    plan: BatchPlan
    #: each input key's message field
    fields: dict[str, str]

    if TYPE_CHECKING:
        def _materialise(self) -> None: ...

    def _value(self, ev: Event, key: str) -> Any:
        """Variable ``key``'s value from message ``ev`` (the one-field rule)."""
        mapped = self.plan.mapped.get(key)
        if mapped is not None:
            return mapped(ev.fields)
        return ev.fields[self.plan.output[2] if key == self.plan.output[1] else self.fields[key]]

    def _note(self, chunk: EventRows | BlockRows, s: int, order: np.ndarray, margin: np.ndarray, atom: np.ndarray,
              out_rows: np.ndarray, paired_out: np.ndarray, qidx: np.ndarray, in_rows: np.ndarray, er: np.ndarray,
              prior: Any, no: int) -> None:
        """The readings' margins counted in the result in the engine's order (``order``), as
        :meth:`~.verdicts.NodeResult.note_margin` counts them one by one; the engine's message margin so far."""
        m, plan = self.m, self.plan
        vals = margin[order]
        j = int(np.argmin(vals))
        i = int(order[j])
        if i < no:
            r = int(out_rows[i])
            ev = chunk[s + r]
            asker = chunk[s + int(in_rows[int(qidx[r])])].where if paired_out[i] else ""
        else:
            r = int(er[i - no])
            ev = chunk[s + r] if r >= 0 else prior[0]
            asker = ""
        text, unit = plan.atoms[int(atom[i])] if atom[i] >= 0 else ("", "")
        few = vals if len(vals) <= KEPT_MARGINS else np.partition(vals, KEPT_MARGINS - 1)[:KEPT_MARGINS]
        m.result.note_margins(1, m._texts[1], float(vals[j]), unit, text, "double", (ev.index, ev.time, ev.where, asker),
                              len(vals), few.tolist())
        last = int(order[-1])
        r = int(out_rows[last]) if last < no else int(er[last - no])
        index = chunk[s + r].index if r >= 0 else prior[0].index
        m._margin_now = (index, float(margin[last]))

    def _questions_after(self, chunk: EventRows | BlockRows, s: int, k: np.ndarray, t: np.ndarray,
                         in_rows: np.ndarray, out_rows: np.ndarray, qidx: np.ndarray, answered: np.ndarray,
                         paired_out: np.ndarray) -> None:
        """The questions the stream keeps after the chunk, the watched one and the input's value, as feeding the
        chunk leaves them (questions.py ``ask``: an unanswered trigger carried to the next question)."""
        m, plan = self.m, self.plan
        ik, okey = plan.trigger, plan.output[1]
        stream = m.stream
        if any(q is None for q in stream._questions):
            self._materialise()
        q0 = stream.latest
        assert q0 is not None
        L, nq = len(k), len(in_rows)
        o0 = m._open
        if o0 is not None:  # closed at the chunk's first event (answered in full: silently)
            o0.reported = True
            m._open, m._due = None, float("inf")
        if not nq:
            return
        # the trigger each question holds: its own, or, when the question before it left its trigger unanswered,
        # that one's (the earliest kept): a chain starts at the first question and after each answered one
        own = np.arange(nq)
        holder = np.maximum.accumulate(np.where(np.concatenate([[True], answered[:-1]]), own, -1))
        first_carry = ik in q0.triggers and ik not in q0.answered_triggers
        total = len(stream._questions) + nq
        keptn = kept_after(total)
        tail = list(range(max(0, nq - min(nq, keptn)), nq))
        out_of = np.full(nq, -1, dtype=np.int64)  # each answered question's answer row
        out_of[qidx[out_rows[paired_out]]] = out_rows[paired_out]
        made: list[Question] = []
        h = m.horizon
        for j in tail:
            r = int(in_rows[j])
            ev = chunk[s + r]
            q = Question(ev, ev.time, {ik: self._value(ev, ik)}, True, "exact")
            q.due = ev.time + h
            hj = int(holder[j])
            q.triggers = {ik: q0.triggers[ik] if hj == 0 and first_carry else
                          ev if hj == j else chunk[s + int(in_rows[hj])]}
            if j + 1 < nq and not answered[j]:
                q.mark("passed", ik)
            if answered[j]:
                oev = chunk[s + int(out_of[j])]
                v = self._value(oev, okey)
                q.answered, q.last_out, q.answer = True, oev, {okey: v}
                q.view = {ik: q.inputs[ik], okey: v}
                q.decided = {1}
                q.mark("answered_triggers", ik)
            made.append(q)
        if first_carry:
            q0.mark("passed", ik)
        # the last question: watched when no slot follows its own, else closed
        lastq = made[-1]
        last_row = int(in_rows[-1])
        follows = bool((t[last_row + 1:] != t[last_row]).any())
        for q in made[:-1]:
            q.reported = True
        if follows:
            lastq.reported = True
        else:
            m._open, m._due = lastq, lastq.due
        drop = max(0, len(stream._questions) + len(made) - keptn)
        stream._questions = (stream._questions + made)[drop:]
        stream._stamps = (stream._stamps + [q.stamp for q in made])[drop:]
        if drop or len(made) < nq:
            stream.forgot = True
        stream.latest = lastq
        m.values[ik] = lastq.inputs[ik]
        m.invalid.pop(ik, None)


__all__ = ["LoneState"]
