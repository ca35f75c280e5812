"""A run of answer pairs judged at once (:mod:`.batch`): which pairs are surely satisfied (or, once
nothing renders them, surely violated) over the chunk's columns, their verdicts and margins counted as
the engine counts them, the rest fed to the engine.

Each pair's formulas are evaluated in float64 with a certificate per row
(:mod:`rclverify.targets.columns`); a pair is taken only where the engine
would give it the same verdict on its fast path: the engine quiet before
it (:meth:`PairRuns._quiet`), the triggers carried to its question its own
(:meth:`PairRuns._carries_own`), an output held for the transport skew
released within the run (:meth:`PairRuns._released`).  The engine's state
after a run is set by :class:`~.batch_state.PairsState`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from rclverify.core.numeric import np

from rclverify.targets.column_margins import RowAtoms
from rclverify.targets.columns import seed
from rclverify.backends.monitors.batch_state import PairsState
from rclverify.backends.monitors.batch_violations import add_records, room
from rclverify.backends.monitors.verdicts import KEPT_MARGINS, Verdict

if TYPE_CHECKING:
    from rclverify.traces.events import Event
    from rclverify.backends.monitors.rows import BlockRows, EventRows


class PairRuns(PairsState):
    """The part of the batch run (:class:`~.batch._Run`) that judges runs of pairs; ``kinds`` each node
    topic's column code (an input's number, -1 the output), ``owing`` per guarantee the code of the input
    triggering it (0: untriggered; empty: none triggered), ``trigger_of`` the input key of each code,
    ``wrong`` whether surely violated pairs are counted in batch, ``batched`` the pairs judged at once."""

    kinds: dict[str, int]
    owing: list[int]
    trigger_of: dict[int, str]
    wrong: bool
    records: bool
    violated_as: str
    batched: int

    if TYPE_CHECKING:
        def feed(self, ev: Event) -> None: ...

        def _full(self) -> bool: ...

    def _pairs(self, chunk: EventRows | BlockRows, at: np.ndarray, kind: np.ndarray, times: np.ndarray,
               cols: dict[str, np.ndarray]) -> int:
        """A run of pairs (their inputs at ``at``): the surely satisfied ones in
        batches, the rest fed to the engine.  Returns the event after the run."""
        plan, m = self.plan, self.m
        okey = plan.output[1]
        # every input as it stands at each pair: the pair's own, else the latest before it (else the engine's)
        tkind = kind[at]
        columns: dict[str, np.ndarray] = {okey: cols[okey][at + 1]}
        seen = np.ones(len(at), dtype=bool)
        src: dict[str, np.ndarray] = {}
        for topic, (key, _, _) in plan.inputs.items():
            mine = tkind == self.kinds[topic]
            idx = np.where(mine, at, -1)
            np.maximum.accumulate(idx, out=idx)
            src[key] = idx
            col = cols[key][np.maximum(idx, 0)]
            if not mine.all():
                before = idx < 0
                first = seed(m.values.get(key), plan.enums.get(key))
                if first is None:  # no value yet, or one the columns do not hold: the engine judges those rows
                    seen &= ~before
                else:
                    col = col.copy()
                    col[before] = first
            columns[key] = col
        owed: list[np.ndarray] | None = None
        if self.owing:  # a question owes a triggered guarantee its own message triggers (another only as carried:
            # the first pair's, _carries_own); one owing none is settled with no answer: the engine's
            owed = [tkind == c if c else np.ones(len(at), dtype=bool) for c in self.owing]
            seen &= np.logical_or.reduce(owed)
        sure = seen.copy()
        judged = [f(columns) for f in plan.formulas]
        na = len(m.assumption)
        for j, (truth, certain) in enumerate(judged):
            holds = np.broadcast_to(truth & certain, sure.shape)
            sure &= holds if owed is None or j < na else holds | ~owed[j - na]
        every = np.arange(len(at))
        margins = [(g(columns)[0], RowAtoms(f, columns, every)) for g, f in zip(plan.margin_values, plan.margins)]
        for j, (value, _) in enumerate(margins):  # a margin the engine would compute in exact arithmetic (0, not
            sure &= value > 0 if owed is None else (value > 0) | ~owed[j]  # positive): its row
        wrong: np.ndarray | None = None
        bad = np.flatnonzero(~sure)
        loose = bad
        if self.wrong:  # the assumptions surely true, the guarantee surely false with a negative margin
            wrong = seen.copy()
            for truth, certain in judged[:-1]:
                wrong &= np.broadcast_to(truth & certain, wrong.shape)
            truth, certain = judged[-1]
            wrong &= np.broadcast_to(~truth & certain, wrong.shape)
            for value, _ in margins:
                wrong &= value < 0
            loose = np.flatnonzero(~(sure | wrong))
        full = wrong is not None and (self.records or self._full())  # records written in batch, or none kept
        p, total = 0, len(at)
        m = self.m
        feed = self.feed
        while p < total:
            if not full and wrong is not None and self._full():
                full = True
            if full:
                bad = loose
            b = int(bad[np.searchsorted(bad, p)]) if len(bad) and bad[-1] >= p else total
            if b > p and m._held:  # an output held for the skew: batch only up to the event that releases it
                limit = m._held[0][1] + m._reach_of(m._held[0][0])
                b = p + int(np.searchsorted(times[at[p:b] + 1], limit, side="right"))
            if b > p and full and wrong is not None and self.held:
                b = self._released(at, times, wrong, p, b)
            if b > p and self._quiet(times[at[p]]) and self._carries_own(int(tkind[p])):
                self._satisfied(chunk, at[p:b], {k: v[p:b] for k, v in src.items()}, times,
                                [(v[p:b], a[p:b]) for v, a in margins], wrong[p:b] if full and wrong is not None
                                else None, [o[p:b] for o in owed] if owed is not None else None)
                p = b
                if p >= total:
                    break
            i = int(at[p])
            feed(chunk[i])
            feed(chunk[i + 1])
            p += 1
        return int(at[-1]) + 2

    def _released(self, at: np.ndarray, times: np.ndarray, wrong: np.ndarray, p: int, b: int) -> int:
        """The end of the run of pairs ``p:b`` whose violated answers the engine would have
        released (judged) within it: a violated output is held for the transport skew and
        released at the first event later than its stamp plus the skew (the questions within
        the skew after it are the run's, each answered by its own output); a run ending
        within the skew of one stops before it."""
        skew = self.m.stream.skew
        while b > p:
            outs = times[at[p:b] + 1]
            held = np.flatnonzero(wrong[p:b] & (outs + skew >= outs[-1]))
            if not len(held):
                break
            b = p + int(held[0])
        return b

    def _carries_own(self, code: int) -> bool:
        """Whether the triggers the latest question left unanswered (carried to the next question,
        questions.py ``ask``) are only the trigger of a pair raised by the input of column code ``code``."""
        last = self.m.stream.latest
        if last is None or not last.triggers:
            return True
        own = self.trigger_of.get(code)
        return all(t == own or t in last.answered_triggers for t in last.triggers)

    def _margins(self, chunk: EventRows | BlockRows, at: np.ndarray,
                 margins: list[tuple[np.ndarray, RowAtoms]], owed: list[np.ndarray] | None = None) -> np.ndarray:
        """Each guarantee's smallest margin over the pairs at ``at`` owing it (``owed``: per guarantee, which
        pairs; ``None``: all) counted in the result, as the engine counts them one by one; returns each pair's
        message margin (the least of the guarantees it owes)."""
        m, plan = self.m, self.plan
        kept_all = m.result.margins
        every = at
        for k, (value, atom) in enumerate(margins, 1):
            if owed is not None:
                sel = owed[k - 1]
                if not bool(sel.any()):
                    continue
                value, atom, at = value[sel], atom[sel], every[sel]
            j = int(np.argmin(value))
            kept = kept_all.get(k)
            if kept is not None and kept.answers and not value[j] < kept.value and \
                    len(kept.lowest) >= KEPT_MARGINS and not value[j] < kept.lowest[-1]:
                kept.answers += len(at)  # none of them is kept: note_margins would only count them
                continue
            a = int(atom[j])
            text, unit = plan.atoms[a] if a >= 0 else ("", "")
            qe, ev = chunk[int(at[j])], chunk[int(at[j]) + 1]
            asker = "" if k in m._alone else qe.where  # an output-only guarantee is judged on no question
            few = value if len(value) <= KEPT_MARGINS else np.partition(value, KEPT_MARGINS - 1)[:KEPT_MARGINS]
            m.result.note_margins(k, m._texts[k], float(value[j]), unit, text, "double",
                                  (ev.index, ev.time, ev.where, asker), len(at), few.tolist())
        values = [v for v, _ in margins] if owed is None else [np.where(o, v, np.inf) for (v, _), o in zip(margins, owed)]
        least: np.ndarray = np.minimum.reduce(values)
        return least

    def _quiet(self, t: float) -> bool:
        """Whether the engine would give no verdict of its own at an input at time ``t`` followed by its answer
        (a pair whose own input or answer was heard later than the lateness bound is no pair: batch.py, ``chunk``,
        :mod:`.batch_late`)."""
        m = self.m
        if m.now > t or m.invalid or m._late_in:  # an unreadable input, or one heard later than the lateness
            return False  # bound before the pair, makes the next questions undecided: the engine's
        o = m._open
        if o is not None and not (o.answered and not o.waiting and (o.followed or o.decided.issuperset(m._need))):
            return False
        last = m.stream.latest
        if last is not None and last.owed and not (last.answered or last.settled or last.reported) and \
                t <= last.event.time + m.horizon:
            return False
        stamps = m.stream._stamps
        return not stamps or stamps[-1] <= t

    def _satisfied(self, chunk: EventRows | BlockRows, at: np.ndarray, src: dict[str, np.ndarray],
                   times: np.ndarray, margins: list[tuple[np.ndarray, RowAtoms]] | None = None,
                   wrong: np.ndarray | None = None, owed: list[np.ndarray] | None = None) -> None:
        """The pairs at ``at`` are surely satisfied, or surely violated where ``wrong``
        (:attr:`wrong`; the first ones' records written as the engine writes them while the run keeps
        records, batch_violations.py, the rest only counted): their verdicts (with their margins, ``margins``:
        per guarantee its values and deciding atoms, an atom read when noted), and the engine's state as
        feeding them sets it."""
        m = self.m
        h = m.horizon
        n = len(at)
        self.batched += n
        t_first = float(times[at[0]])  # the chunk's time column holds each event's time: no event made for it
        # the watched question: closed silently when its horizon passed, else followed by the first new question
        o = m._open
        if o is not None and t_first > m._due:
            o.reported = True
            m._open, m._due = None, float("inf")
        last = m.stream.latest
        if last is not None and t_first <= last.event.time + h:
            last.followed = True
        carried: dict[str, Event] = {}
        if last is not None and last.triggers:  # its triggers no output answered go to the first new question
            for t, tev in last.triggers.items():  # (questions.py, ``ask``)
                if t not in last.answered_triggers:
                    carried[t] = tev
                    last.mark("passed", t)
        if m._open is not None and m._open.followed:
            m._open, m._due = None, float("inf")
        result = m.result
        result.events += 2 * n
        bad = int(np.count_nonzero(wrong)) if wrong is not None else 0
        result.counts["satisfied"] += n - bad
        result.semantics["exact"] += n - bad
        if bad:
            result.counts["violated"] += bad
            assert wrong is not None
            kept = min(room(m), bad) if self.records else 0  # the first ones' records, as the engine writes them
            if kept:
                add_records(self, chunk, at, src, np.flatnonzero(wrong)[:kept].tolist(), self.violated_as)
            result.violations_dropped += bad - kept
        result.accepted += n
        least = self._margins(chunk, at, margins, owed) if margins else None
        if m.on_verdict is not None:
            name, emit = m.node.name, m.on_verdict
            for j, i in enumerate(at.tolist()):
                qe, ev = chunk[i], chunk[i + 1]
                emit(Verdict(name, "satisfied", ev.index, ev.time, ev.where, ev.topic, ev.time, 0, {}, "", "exact",
                             qe.where, float(least[j]) if least is not None else None))
        newest = self._keep_questions(chunk, at, src, times, carried)
        self._remember_outputs(chunk, at, times, wrong, bad, newest)


__all__ = ["PairRuns"]
