"""The engine's state after the batch path judged a run of pairs at once
(:mod:`.batch`): the questions the stream keeps (the newest made at once,
the older ones made when the engine may look them up), the outputs it
remembers for the transport skew and for a revision to withdraw, the
values, the clock and the watched question, each as feeding the pairs one
by one sets it (docs/semantics.md, "Questions"; docs/monitors.md, the batch
path)."""
from __future__ import annotations

from itertools import repeat
from typing import cast

from rclverify.core.numeric import np

from rclverify.traces.events import Event
from rclverify.traces.questions import KEPT, Question, QuestionStream, kept_after
from rclverify.backends.monitors.answered import AnsweredRun, RecentOutput
from rclverify.backends.monitors.batch_plan import BatchPlan
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.backends.monitors.rows import BlockRows, EventRows


def _kept(stream: QuestionStream) -> list[Question | None]:
    """The questions ``stream`` keeps as a batch run leaves them: ``None`` for
    a ghost's question, made when the engine may look it up (``_materialise``)."""
    return cast("list[Question | None]", stream._questions)


class PairsState:
    """The part of the batch run (:class:`~.batch._Run`) that sets the engine's
    state after a run of pairs; ``m`` is the node's engine, ``plan`` its batch
    plan, ``ghosts`` the runs whose older questions the stream keeps unmade."""

    m: NodeMonitor
    plan: BatchPlan
    ghosts: list[AnsweredRun]
    #: whether a violated answer is held for the transport skew (set by the batch run)
    held: bool

    def _keep_questions(self, chunk: EventRows | BlockRows, at: np.ndarray, src: dict[str, np.ndarray],
                        times: np.ndarray, carried: dict[str, Event]) -> Question:
        """The stream's questions after the pairs at ``at``, as feeding them keeps them (the
        newest made now, the older ones when the engine may look them up; ``carried``: the
        triggers the first of them takes from the question before it); returns the newest."""
        m, n = self.m, len(at)
        stream = m.stream  # the older questions are made when the engine may look them up: _materialise
        old = len(stream._questions)
        total = old + n
        keptn = kept_after(total)
        tail = at[-min(n, keptn, 2 * KEPT):]
        where = {k: v[len(at) - len(tail):] for k, v in src.items()}
        seed = {k: m.values[k] for k in m._in_keys}
        ghost = AnsweredRun(chunk, tail, where, seed, carried if len(tail) == n else {})
        newest = ghost.question(len(tail) - 1, self)
        drop = max(0, old + len(tail) - keptn)
        # an output held for the skew: its release reads the questions within the skew after it, so they are made
        made = [ghost.question(j, self) for j in range(len(tail) - 1)] if m._held else [None] * (len(tail) - 1)
        stream._questions = (_kept(stream) + made + [newest])[drop:]  # type: ignore[assignment]  # None: made later
        stream._stamps = (stream._stamps + times[tail].tolist())[drop:]
        if drop or len(tail) < n:
            stream.forgot = True
        stream.latest = newest
        if len(tail) > 1 and not m._held:
            self.ghosts.append(ghost)
            left = _kept(stream).count(None)  # the ghosts the stream still keeps: the latest of them
            while self.ghosts and sum(len(g.at) - 1 for g in self.ghosts[1:]) >= left:
                del self.ghosts[0]
        return newest

    def _remember_given(self, chunk: EventRows | BlockRows, at: np.ndarray, wrong: np.ndarray | None) -> None:
        """The verdicts given to the latest answers of the pairs at ``at`` (``satisfied``,
        ``exact``; ``violated`` where ``wrong``), as the engine keeps them for a revision to
        withdraw (late.py); a chunk's rows are its events in order (row ``i`` is event
        ``chunk[0].index + i``)."""
        given = self.m._given
        assert given.maxlen is not None  # the engine keeps a bounded deque
        last = at[-given.maxlen:]
        base = chunk[0].index
        kinds = (np.where(wrong[-given.maxlen:], "violated", "satisfied").tolist() if wrong is not None
                 else repeat("satisfied"))
        given.extend(zip((last + 1 + base).tolist(), kinds, repeat("exact")))

    def _remember_outputs(self, chunk: EventRows | BlockRows, at: np.ndarray, times: np.ndarray,
                          wrong: np.ndarray | None, bad: int, newest: Question) -> None:
        """The engine's state after the pairs at ``at`` (``bad`` of them violated, where
        ``wrong``): the outputs it remembers for the transport skew, the values, the clock and
        the watched question, as feeding them sets them."""
        plan, m = self.plan, self.m
        okey, keys, ofield = plan.output[1], plan.keys, plan.output[2]
        # the answers' entries (the skew's, late.py's), each event made if the engine reads it (answered.py)
        recent = m._recent
        assert recent.maxlen is not None  # the engine keeps a bounded deque
        if bad and wrong is not None and self.held:  # a violated output is held for the skew, then kept as released (engine.py)
            released = at[wrong][-recent.maxlen:] + 1
            m._released.extend(map(RecentOutput, repeat(chunk), released.tolist(), times[released].tolist(),
                                   repeat(okey), repeat(ofield), repeat(plan.mapped.get(okey))))
            outs = at[~wrong][-recent.maxlen:] + 1
        else:
            outs = at[-recent.maxlen:] + 1
        recent.extend(map(RecentOutput, repeat(chunk), outs.tolist(), times[outs].tolist(), repeat(okey),
                          repeat(ofield), repeat(plan.mapped.get(okey))))
        self._remember_given(chunk, at, wrong)
        values = m.values
        for k in keys:
            values[k] = newest.inputs[k]
            m.invalid.pop(k, None)
        values[okey] = newest.answer[okey]
        m.invalid.pop(okey, None)
        m.heard_answer = True  # the pairs' outputs were heard (engine.py: judging starts at the first one)
        m._open, m._due = newest, newest.due
        last_out = float(times[at[-1] + 1])
        if last_out > m.now:
            m.now = last_out
        if last_out > m._hi:  # the latest stamp judged (a pair's rows have no stamp of their own)
            m._hi = last_out


__all__ = ["PairsState", "_kept"]
