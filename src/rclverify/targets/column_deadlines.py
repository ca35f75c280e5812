"""Deadline obligations resolved over columns: when each one's clock passes it, and which output answers it.

The batch deadline judge (:mod:`rclverify.backends.monitors.batch_deadlines`)
holds a chunk of a run as columns: each row's time in integer nanoseconds
(:func:`ns_column`, the deadline monitor's :func:`~rclverify.traces.events.to_ns`
of each row's time, exactly), which rows are outputs, and one row per
obligation (an accepted trigger and one timed guarantee: its row, its
deadline in ns, its input value).  Over times that never go back
(docs/semantics.md, "Deadlines"):

* an obligation **expires** at the first row stamped strictly after its
  deadline (:func:`expiries`; the monitor's clock is the latest stamp
  read, and "within" includes the deadline itself);
* it is **answered** by the first output row after its own row on which
  its guarantee is true (:func:`first_answers`): the outputs before it
  are those that did not satisfy it.  Each pair is judged by the compiled
  guarantee's certificate (:mod:`.columns`); a pair not surely decided
  in exact arithmetic stops the search (``None``): the chunk is then the
  streaming monitor's.

Everything here is a pure function of arrays: which verdict those two rows
give, and in what order, is the judge's (the rules of
:mod:`rclverify.backends.monitors.deadlines`).
"""
from __future__ import annotations

from typing import Callable, Mapping, Sequence

from rclverify.core.numeric import np

#: A compiled guarantee over columns (``in.x``, ``out.y`` -> arrays) -> (truth, sure).
Judge = Callable[[Mapping[str, np.ndarray]], tuple[np.ndarray, np.ndarray]]
#: The most outputs one search looks at past an obligation before the chunk is streamed instead: a
#: guarantee no output satisfies would make the search quadratic in the chunk.
PASSES = 64


def ns_column(times: np.ndarray) -> np.ndarray | None:
    """Each time (float64 seconds) as integer nanoseconds exactly as
    :func:`~rclverify.traces.events.to_ns` gives it (the whole seconds split
    off, the fraction's nanoseconds rounded half to even), int64; ``None``
    when a time is not finite or beyond int64's nanoseconds."""
    if not len(times):
        return np.zeros(0, dtype=np.int64)
    if not bool(np.isfinite(times).all()) or float(np.abs(times).max()) >= 9.0e9:
        return None
    whole = np.floor(times)
    frac: np.ndarray = np.rint((times - whole) * 1e9).astype(np.int64)
    ns: np.ndarray = whole.astype(np.int64) * 1_000_000_000 + frac
    return ns


def expiries(ns: np.ndarray, due: np.ndarray) -> np.ndarray:
    """For each deadline ``due`` (int64 ns), the first row whose time ``ns`` (nondecreasing) is past it;
    ``len(ns)`` where none is."""
    out: np.ndarray = np.searchsorted(ns, due, side="right")
    return out


def first_answers(start: np.ndarray, outputs: np.ndarray, which: np.ndarray, inputs: np.ndarray,
                  answers: np.ndarray, judges: Sequence[Judge | None], in_key: str, out_key: str
                  ) -> np.ndarray | None:
    """Each obligation's answering row: the first output row after row ``start`` (``-1``: before the chunk)
    among ``outputs`` (the output rows, increasing) on which its guarantee holds; ``-1`` where none in the
    chunk does.  ``which``: each obligation's guarantee (an index into ``judges``; ``None``: a guarantee no
    output answers); ``inputs``: its input value; ``answers``: each output row's value (aligned with
    ``outputs``).  ``None`` when a pair is not surely decided or the search passes :data:`PASSES` outputs."""
    m = len(start)
    found = np.full(m, -1, dtype=np.int64)
    ptr = np.searchsorted(outputs, start, side="right")
    live = np.array([j is not None for j in judges], dtype=bool)
    idx = np.flatnonzero(live[which]) if m else np.zeros(0, dtype=np.int64)
    step = 0
    while idx.size:
        pos = ptr[idx] + step
        has = pos < len(outputs)
        idx, pos = idx[has], pos[has]
        if not idx.size:
            break
        if step >= PASSES:
            return None
        hit = np.zeros(idx.size, dtype=bool)
        for g, judge in enumerate(judges):
            if judge is None:
                continue
            sel = np.flatnonzero(which[idx] == g)
            if not sel.size:
                continue
            truth, sure = judge({in_key: inputs[idx[sel]], out_key: answers[pos[sel]]})
            truth, sure = np.broadcast_to(truth, sel.shape), np.broadcast_to(sure, sel.shape)
            if not bool(sure.all()):
                return None
            hit[sel] = truth
        found[idx[hit]] = outputs[pos[hit]]
        idx = idx[~hit]
        step += 1
    return found


__all__ = ["PASSES", "Judge", "expiries", "first_answers", "ns_column"]
