"""Lone triggers and lone answers judged in batch: a triggered node's run where pairs come one or two at a time.

The batch path (:mod:`.batch`) judges runs of answer pairs over columns
and feeds a chunk of short runs to the engine whole (:data:`~.batch.MIN_RUN`).
A node whose one guarantee is ``triggered by`` its one input, answered
by its one output, has such runs when triggers and answers come apart: a
trigger with no answer at its stamp (a **lone trigger**), an answer with
no trigger at its stamp (a **lone answer**).  :class:`LoneSlots` judges
such a chunk over its columns when it is **clean**, as the engine would
judge it event by event (docs/semantics.md, "Questions", "Transport
skew"; docs/monitors.md, the batch path):

* the chunk is **slots**: each the events of one time, a trigger, an answer, or a
  trigger then its answer; a slot comes more than the horizon (and 1 us)
  after the slot before it, so every question is closed before the next
  slot and no answer of a later slot is part of its answer;
* a trigger raises a question owing the guarantee (it carries the trigger
  of a question before it that no answer in its horizon answered, the
  earliest kept); the answer of its own slot answers it: ``satisfied``,
  its margin on the question;
* a lone answer is judged against the latest question, past its horizon
  (no part of its answer: it answers no trigger): ``satisfied``, its
  margin on no question;
* a question no answer answered is closed at the next slot: with a transport
  skew, the last answer stamped within the skew before it is read as its
  answer (closing.py, ``_early_answer``: its margin counted on no
  question), then ``inconclusive`` (unanswered).

**Clean**: every event on the node's two topics, its field mapped, no
header stamp, times in order from the engine's clock on; slots as above;
every reading above (a pair, a lone answer on its question's input, an
early answer on the unanswered question's input) surely true in exact
arithmetic (:mod:`rclverify.targets.columns`) with a positive margin when
margins are asked.  The engine before the chunk is **ready**: nothing held,
unread or late, an output heard, the latest question owed, the last kept,
closed or watched as one of the two shapes above.  The engine is fed events
one by one until it is ready (at most :data:`WARM`); a chunk that is not
clean is fed to it whole.  After a clean chunk the engine's state is set as
feeding it would set it (the values, the clock, the watched question, the
questions the stream keeps, the outputs remembered for the skew, the
verdicts given, the counts and margins).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping

from rclverify.core.numeric import np

from rclverify.traces.events import Event
from rclverify.targets.columns import block_column, seed
from rclverify.backends.monitors.answered import RecentOutput
from rclverify.backends.monitors.skew import within_before
from rclverify.backends.monitors.batch_late import own_times
from rclverify.backends.monitors.batch_lone_state import LoneState
from rclverify.backends.monitors.verdicts import Verdict

if TYPE_CHECKING:
    from rclverify.backends.monitors.batch_plan import BatchPlan
    from rclverify.backends.monitors.engine import NodeMonitor
    from rclverify.backends.monitors.rows import BlockRows, EventRows

#: The most events fed to the engine at a chunk's start until its state is one the slots judge reads.
WARM = 16
#: How far (s) past the horizon a slot comes after the one before it at least: the engine's integer-nanosecond
#: reading of "within the horizon" (closing.py ``_at_due``) is asked only nearer than 1 us.
_APART = 1e-6


def lone_eligible(m: NodeMonitor, plan: BatchPlan) -> bool:
    """Whether the node's chunks of lone triggers and answers may be judged by :class:`LoneSlots`: one guarantee,
    triggered by the one input, no assumption, no output-only guarantee, no ``first(...)``, no window."""
    return bool(plan.trigger) and len(plan.inputs) == 1 and len(m.guarantees) == 1 and not m.assumption and \
        m._trigger == {1: plan.trigger} and not m._alone and not plan.widths and not m.first.keys and \
        plan.output[3] in ("real", "enum")


class LoneSlots(LoneState):
    """The part of the batch run (:class:`~.batch._Run`) that judges a chunk of lone triggers and answers
    (module docstring); ``m`` the engine, ``plan`` its batch plan; the state it leaves is
    :class:`~.batch_lone_state.LoneState`'s."""

    m: NodeMonitor
    plan: BatchPlan
    ghosts: list[Any]
    batched: int

    if TYPE_CHECKING:
        def feed(self, ev: Event) -> None: ...

    def _lone(self, chunk: EventRows | BlockRows, kind: np.ndarray, times: np.ndarray) -> int:
        """Judge ``chunk`` (``kind``: each row's column code, 1 the input, -1 the output) after feeding the engine
        until it is ready; returns the first row left for the caller to feed (``len(chunk)``: all judged)."""
        n, s = len(chunk), 0
        while s < n and not self._ready(float(times[s])):
            if s >= WARM:
                return s
            self.feed(chunk[s])
            s += 1
        return self._slots(chunk, kind, times, s) if s < n else s

    def _ready(self, t0: float) -> bool:
        """Whether the engine's state before an event at ``t0`` (s) is one :meth:`_slots` reads."""
        m = self.m
        if m._held or m.invalid or m._late_in or m._unread or m._wins or not m.heard_answer or m.now > t0 \
                or m._hi > t0:
            return False
        stream = m.stream
        q = stream.latest
        if q is None or not q.owed or q.settled or q.followed or q.waiting or not stream._questions or \
                stream._questions[-1] is not q or stream._stamps[-1] != q.stamp or q.stamp > t0 or \
                not t0 - q.due >= _APART or seed(q.inputs.get(self.plan.trigger), self._codes_in) is None:
            return False
        o = m._open
        if o is None:
            return q.reported
        if o is not q or q.reported:
            return False
        return (q.answered and q.decided.issuperset(m._need)) or not q.answered

    @property
    def _codes_in(self) -> dict[str, int] | None:
        return self.plan.enums.get(self.plan.trigger)

    def _slots(self, chunk: EventRows | BlockRows, kind: np.ndarray, times: np.ndarray,  # long: the clean
               s: int) -> int:  # checks and the readings share the chunk's columns, one pass
        """Judge rows ``s:e`` of ``chunk`` when clean (module docstring; ``e`` the first row of another topic, else
        the end) and set the engine's state; returns ``e``, or ``s`` (nothing changed) when not clean."""
        m, plan = self.m, self.plan
        other = np.flatnonzero(kind[s:] == 0)
        e = s + int(other[0]) if len(other) else len(chunk)
        L = e - s
        k, t = kind[s:e], times[s:e]
        if L < 2 or not bool(((k == 1) | (k == -1)).all()) or bool((np.diff(t) < 0).any()):
            return s
        unstamped = chunk.unstamped()
        if unstamped is not None and not bool(unstamped[s:e].all()):
            return s
        own = own_times(chunk)  # a source time or a lateness of its own: the engine's (batch_late.py)
        if own is not None and bool(own[s:e].any()):
            return s
        new = np.ones(L, dtype=bool)
        new[1:] = t[1:] != t[:-1]
        starts = np.flatnonzero(new)
        lens = np.diff(np.append(starts, L))
        if int(lens.max()) > 2:
            return s
        two = starts[lens == 2]
        if bool((k[two] != 1).any()) or bool((k[two + 1] != -1).any()):
            return s
        h = m.horizon
        st = t[starts]
        if len(st) > 1 and bool((st[1:] - (st[:-1] + h) < _APART).any()):
            return s
        ik, (otopic, okey, ofield, okind) = plan.trigger, plan.output
        itopic = next(iter(plan.inputs))
        _, ifield, ikind = plan.inputs[itopic]
        in_rows, out_rows = np.flatnonzero(k == 1), np.flatnonzero(k == -1)
        good_in, col_in = _typed(chunk, in_rows + s, ifield, ikind, plan.enums.get(ik, {}))
        good_out, col_out = _typed(chunk, out_rows + s, ofield, okind, plan.enums.get(okey, {}))
        if not (bool(good_in.all()) and bool(good_out.all())):
            return s
        q0 = m.stream.latest
        assert q0 is not None  # _ready
        in0 = seed(q0.inputs[ik], plan.enums.get(ik))
        # each row's question: the latest trigger at or before it (-1: q0); an output is paired with a trigger
        # of its own slot
        is_in = k == 1
        qidx = np.cumsum(is_in) - 1
        nq = len(in_rows)
        qin = np.concatenate([[in0], col_in]).astype(col_in.dtype)  # (q0 first)
        paired_out = np.zeros(len(out_rows), dtype=bool)
        if len(two):
            paired_out[np.searchsorted(out_rows, two + 1)] = True
        answered = np.zeros(nq, dtype=bool)
        answered[qidx[out_rows[paired_out]]] = True
        # the slot each row is in, and the row that starts the next slot (L: none)
        slot = np.cumsum(new) - 1
        nxt = np.append(starts[1:], L)[slot]
        # questions closed unanswered within the chunk: q0 when watched and unanswered, each lone trigger
        # followed by a slot; closed at the next slot's first row
        o0 = m._open
        close_q: list[int] = []
        close_at: list[int] = []
        if o0 is not None and not o0.answered:
            close_q.append(-1)
            close_at.append(0)
        lone_q = np.flatnonzero(~answered & (nxt[in_rows] < L))
        close_q += lone_q.tolist()
        close_at += nxt[in_rows[lone_q]].tolist()
        # the early answer each reads (closing.py ``_early``): the last output before its trigger, within the skew
        skew = m.stream.skew
        last_out = np.maximum.accumulate(np.where(k == -1, np.arange(L), -1))
        prior = m._recent[-1] if m._recent else None
        prior_v = seed(prior[2].get(okey), plan.enums.get(okey)) if prior is not None else None
        if prior is not None and prior_v is None:
            return s
        out_full = np.zeros(L, dtype=col_out.dtype)
        out_full[out_rows] = col_out
        early_q: list[int] = []  # (into close_q) those with an early answer
        early_row: list[int] = []  # its row (-1: the engine's last remembered output)
        cq = np.array(close_q, dtype=np.int64)
        if skew and len(cq):  # over columns, in doubles
            own = cq >= 0
            trig = in_rows[np.maximum(cq, 0)] if nq else np.zeros(len(cq), dtype=np.int64)
            r_at = np.where(own, last_out[trig], -1)
            stamp = np.where(own, t[trig], q0.stamp)
            at = np.where(r_at >= 0, t[np.maximum(r_at, 0)], float(prior[1]) if prior is not None else np.nan)
            hit = within_before(at, stamp, skew)  # (NaN: no output remembered, never within)
            early_q, early_row = np.flatnonzero(hit).tolist(), r_at[hit].tolist()
        # the readings: each output on its question's input, each early answer on its question's
        r_in = np.concatenate([qin[qidx[out_rows] + 1],
                               qin[cq[np.array(early_q, dtype=np.int64)] + 1]])
        er = np.array(early_row, dtype=np.int64)
        r_out = np.concatenate([col_out, np.where(er >= 0, out_full[np.maximum(er, 0)],
                                                  prior_v if prior_v is not None else 0)]).astype(col_out.dtype)
        margin: np.ndarray | None = None
        atom: np.ndarray | None = None
        if len(r_in):
            cols = {ik: r_in, okey: r_out}
            truth, certain = plan.formulas[0](cols)
            if not bool(np.broadcast_to(truth & certain, r_in.shape).all()):
                return s
            if plan.margins:
                margin, atom = plan.margins[0](cols)
                if not bool((margin > 0).all()):
                    return s
        self._apply(chunk, s, k, t, in_rows, out_rows, qidx, answered, paired_out, close_q, close_at, early_q,
                    er, margin, atom, prior)
        return e

    def _apply(self, chunk: EventRows | BlockRows, s: int, k: np.ndarray, t: np.ndarray,  # long: the order,
               in_rows: np.ndarray,  # the verdicts and the state read the same arrays
               out_rows: np.ndarray, qidx: np.ndarray, answered: np.ndarray, paired_out: np.ndarray,
               close_q: list[int], close_at: list[int], early_q: list[int], er: np.ndarray,
               margin: np.ndarray | None, atom: np.ndarray | None, prior: Any) -> None:
        """The verdicts of a clean chunk in the engine's order, then the engine's state (module docstring)."""
        m, plan = self.m, self.plan
        L, nq, no = len(k), len(in_rows), len(out_rows)
        ik, okey = plan.trigger, plan.output[1]
        q0 = m.stream.latest
        assert q0 is not None
        result = m.result
        name = m.node.name
        # the engine's order: a question closed at a slot comes before the slot's events; its early answer's
        # margin before its verdict
        pos_out = 2 * out_rows + 1
        pos_close = 2 * np.array(close_at, dtype=np.int64)
        if margin is not None and atom is not None:
            pos = np.concatenate([pos_out, pos_close[np.array(early_q, dtype=np.int64)]])
            order = np.argsort(pos, kind="stable")
            self._note(chunk, s, order, margin, atom, out_rows, paired_out, qidx, in_rows, er, prior, no)
        reason = (f"unanswered: no output within {m.horizon} s of the question at {{}} (a finite run cannot show the "
                  "answer never comes; a deadline `triggered by ... within` would fail)")
        # the verdicts in order: (position, kind 1 an output's / 0 a closed question's, its row or question)
        pos_all = np.concatenate([pos_out, pos_close])
        what_all = np.concatenate([np.ones(no, dtype=np.int64), np.zeros(len(close_q), dtype=np.int64)])
        x_all = np.concatenate([out_rows, np.array(close_q, dtype=np.int64)])
        order_all = np.argsort(pos_all, kind="stable")
        base = s

        def qev(j: int) -> Event:
            """Question ``j``'s trigger message (-1: the question before the chunk's)."""
            got: Event = q0.event if j < 0 else chunk[base + int(in_rows[j])]
            return got
        result.counts["satisfied"] += no
        if "exact" in result.semantics:
            result.semantics["exact"] += no
        if close_q:
            result.counts["inconclusive"] += len(close_q)
            if result.first_inconclusive is None:
                e = qev(close_q[0])  # (closed in the order they were raised)
                result.first_inconclusive = {"event": e.index, "time": e.time, "where": e.where,
                                             "reason": reason.format(e.where)}
        emit = m.on_verdict
        tail = order_all[-(m._given.maxlen or 256):]
        acts = zip(pos_all[order_all].tolist(), what_all[order_all].tolist(), x_all[order_all].tolist()) \
            if emit is not None else iter(())
        least = margin[:no] if margin is not None else None
        out_at = {r: j for j, r in enumerate(out_rows.tolist())} if emit is not None else {}
        if emit is not None:
            for p, what, x in acts:  # (int, int, int)
                if what:
                    ev = chunk[base + x]
                    j = out_at[x]
                    qw = qev(int(qidx[x])).where
                    emit(Verdict(name, "satisfied", ev.index, ev.time, ev.where, ev.topic, ev.time, 0, {}, "",
                                 "exact", qw, float(least[j]) if least is not None else None))
                else:
                    e = qev(x)
                    emit(Verdict(name, "inconclusive", e.index, e.time, e.where, e.topic,
                                 max(float(t[p // 2]), e.time), 0, {}, reason.format(e.where), "", "", None))
        first_index = chunk[base].index if len(chunk) > base else 0
        q0_index = q0.event.index  # row r is event first_index + r (a chunk's rows are its events in order)
        m._given.extend((first_index + x, "satisfied", "exact") if what else
                        (first_index + int(in_rows[x]) if x >= 0 else q0_index, "inconclusive", "")
                        for what, x in zip(what_all[tail].tolist(), x_all[tail].tolist()))
        self._questions_after(chunk, s, k, t, in_rows, out_rows, qidx, answered, paired_out)
        # the values, the clock, the outputs remembered, the counts
        values = m.values
        if no:
            last = chunk[base + int(out_rows[-1])]
            values[okey] = self._value(last, okey)
            m.heard_answer = True
            recent = m._recent
            rec = out_rows[-(recent.maxlen or 64):] + base
            mapped = plan.mapped.get(okey)
            recent.extend(RecentOutput(chunk, int(i), float(t[i - base]), okey, plan.output[2], mapped)
                          for i in rec.tolist())
        last_t = float(t[-1])
        if last_t > m.now:
            m.now = last_t
        if last_t > m._hi:
            m._hi = last_t
        result.events += L
        result.accepted += nq
        self.batched += no


def _typed(chunk: EventRows | BlockRows, rows: np.ndarray, field: str, kind: str, codes: Mapping[str, int]
           ) -> tuple[np.ndarray, np.ndarray]:
    """``chunk.typed``; for a log block with no event carried before it, the columns kept with the block
    (:func:`~rclverify.targets.columns.block_column`: a deadline judge on the same run read them first)."""
    block = getattr(chunk, "block", None)
    if hasattr(block, "kept") and not getattr(chunk, "head", True):
        return block_column(block, rows, field, kind, codes)
    return chunk.typed(rows, field, kind, codes)


__all__ = ["WARM", "LoneSlots", "lone_eligible"]
