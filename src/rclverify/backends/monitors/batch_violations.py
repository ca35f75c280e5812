"""The violation records of answer pairs the batch path judges surely violated (:mod:`.batch_pairs`),
written as the streaming engine writes them.

The engine keeps the first :data:`~.verdicts.KEPT_VIOLATIONS` violations of a
run as records (closing.py, ``_violation``) and only counts the rest.  Where
the batch path takes a surely violated pair (one guarantee, read against a
question, no verdict callback, no declared tolerance that could make it
hold: :attr:`.batch._Run.wrong`), the engine's record of that pair is fully
determined by the pair: its output event (``event``, ``time``, ``where``),
the guarantee (1) and its text, the values of the question and its answer
rendered by the engine's own renderer (``_rendered``), the reason
``guarantee 1 is false on the output at W answering the question at Q``
with the arithmetics that agreed (:func:`~.verdicts.in_all`), the semantics
(``exact``, and ``double`` where the double reading could differ:
:func:`~rclverify.semantics.floatsens.float_sensitive`, as
:func:`~rclverify.semantics.floatsem.judge` tries them), and the question's
event (``trigger``, ``trigger_time``, ``trigger_where``).  A held output (the
transport skew) is released with no other reading, since every question
within the skew after it is answered by its own output within the run
(:meth:`.batch_pairs.PairRuns._released`), so the reason is the one reading's.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.core.numeric import np

from rclverify.semantics.floatsens import float_sensitive
from rclverify.backends.monitors.answered import AnsweredRun
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.backends.monitors.rows import BlockRows, EventRows
from rclverify.backends.monitors.verdicts import KEPT_VIOLATIONS, in_all

if TYPE_CHECKING:
    from rclverify.backends.monitors.shapes import Violation


def violated_semantics(m: NodeMonitor) -> str:
    """The semantics ``judge`` gives a false verdict of ``m``'s one guarantee with no tolerance declared:
    ``exact``, with ``double`` when the double reading could give another truth."""
    return "exact, double" if float_sensitive(m.guarantees[0], m.checked, m.node) else "exact"


def room(m: NodeMonitor) -> int:
    """How many more violations ``m``'s result keeps as records (the rest are counted only: closing.py)."""
    return max(KEPT_VIOLATIONS - len(m.result.violations), 0)


def add_records(run: Any, chunk: EventRows | BlockRows, at: np.ndarray, src: dict[str, np.ndarray],
                rows: list[int], semantics: str) -> None:
    """The records of the violated pairs ``rows`` (positions in ``at``, in order) added to the result as the
    engine adds them.  ``run``: the batch run (its engine ``m``, plan and fields, :meth:`.AnsweredRun.question`);
    ``src``: per input key, the position in ``chunk`` of the message that set it at each pair (< 0: the value
    before the run, read from the engine, which the caller has not changed yet)."""
    m: NodeMonitor = run.m
    seed = {k: m.values[k] for k in m._in_keys}
    answered = AnsweredRun(chunk, at, src, seed)
    text = m._texts.get(1, "")
    said = in_all(semantics)
    result = m.result
    for j in rows:
        q = answered.question(j, run)
        qe = q.event
        ev = chunk[int(at[j]) + 1]
        assert q.view is not None  # made by question()
        record: Violation = {"event": ev.index, "time": ev.time, "where": ev.where, "guarantee": 1, "formula": text,
                             "values": m._rendered(q.view),
                             "reason": f"guarantee 1 is false on the output at {ev.where} answering the question at "
                                       f"{qe.where}{said}",
                             "semantics": semantics, "trigger": qe.index, "trigger_time": qe.time,
                             "trigger_where": qe.where}
        result.add_violation(record)


__all__ = ["add_records", "room", "violated_semantics"]
