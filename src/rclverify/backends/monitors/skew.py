"""Transport skew: an answer received just before its question.

A monitor sees each topic over its own connection (a ROS 1 TCPROS link per
publisher, a DDS reader per topic) and stamps an unstamped message when its
callback runs.  A node that answers an input within a millisecond can have
its answer's callback run before the input's: measured on the case study's
live run on a loaded 2-core machine, ``/radiationStatus`` was stamped 0.13 ms
before the ``/r`` reading it answers, in 3 of 6 runs.  Under the rule "an
answer comes after its question" (docs/monitors.md) that answer answers
nothing, and the reading is reported ``violated`` (no output): a false alarm
on a correct node.

The ``skew`` of the mapping (seconds, default :data:`DEFAULT_SKEW_S`) bounds
how far apart two messages may be stamped in the other order than they were
published.  An output received at most ``skew`` before a question is an
*early candidate*: it may be that question's answer, or a stale answer to an
earlier one, and the monitor cannot tell which.  It is therefore used only
where both readings give the same verdict, or to withhold a verdict:

* no output came after the question within the horizon (today's
  ``violated``, no output) and a guarantee is false on the early candidate:
  ``violated`` with that guarantee (either the node answered falsely, or it
  did not answer: false in both readings);
* every guarantee holds on it: ``inconclusive`` (the answer, or a stale
  output and no answer: the two readings disagree), never ``satisfied``;
* undecided on it: ``inconclusive`` as well.

An early candidate never turns a verdict ``satisfied``: a stale output is
never accepted as an answer (issue 39, "no wrong green").
"""
from __future__ import annotations

import math
from collections import deque
from typing import Any, Mapping

from ...traces.events import Event

#: The default transport skew (s): five of CPython's 5 ms thread switch
#: intervals, the time a receiving thread may wait for the interpreter on a
#: loaded machine, rounded up.  ``skew: 0`` in the mapping turns it off.
DEFAULT_SKEW_S = 0.02


def parse_skew(value: Any) -> float | None:
    """``value`` as a skew in seconds (finite, >= 0, not a boolean), else ``None``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    v = float(value)
    return v if math.isfinite(v) and v >= 0 else None


class EarlyOutputs:
    """The outputs a node published lately, for the questions that got none.

    ``remember((event, fresh))`` is called for each output event (``fresh``:
    the event outputs it set, ``out.x`` -> value, a dict the caller no
    longer changes): one append, nothing else on the monitor's hot path.
    :meth:`before` is asked only when a question's horizon passed with no
    output after it; since every output stamped at or after a question
    answers it, the outputs remembered since that question are none (or
    stamped before it), and its early candidates are still at the end of
    the queue.  At most :data:`KEPT` outputs are kept, so memory stays flat
    at any rate."""

    __slots__ = ("skew", "_recent", "remember")

    #: Outputs kept at most (older ones are forgotten as new ones come).
    KEPT = 256

    def __init__(self, skew: float) -> None:
        self.skew = skew
        self._recent: deque[tuple[Event, Mapping[str, Any]]] = deque(maxlen=self.KEPT)
        self.remember = self._recent.append

    def before(self, stamped: float) -> tuple[Event, dict[str, Any]] | None:
        """The early candidate of a question stamped at ``stamped`` (s): the
        outputs stamped at most ``skew`` before it (or at its stamp, logged
        before it), merged in order (a later one overrides), with the first
        such event; ``None`` when there is none."""
        floor = stamped - self.skew
        found: list[tuple[Event, Mapping[str, Any]]] = []
        for ev, fresh in reversed(self._recent):
            at = ev.stamped
            if at < floor:
                break
            if at <= stamped:
                found.append((ev, fresh))
        if not found:
            return None
        outs: dict[str, Any] = {}
        for _, fresh in reversed(found):
            outs.update(fresh)
        return found[-1][0], outs


def early_reason(k: int | None, out: Event, trigger: Event, skew: float, horizon: float) -> str:
    """The verdict's sentence for an early candidate: guarantee ``k`` false on
    it (``violated``), or ``None`` (it holds or is undecided: ``inconclusive``)."""
    gap = max(trigger.stamped - out.stamped, 0.0) * 1000
    said = (f"the output at {out.where} was received {gap:.2f} ms before the input at {trigger.where} "
            f"(within the transport skew of {skew:g} s) and no output came after it within {horizon} s")
    if k is not None:
        return (f"guarantee {k} is false on the output at {out.where}: {said}; whether it answered this input "
                "or was a stale answer to an earlier one, this input got no answer that meets the guarantee")
    return (f"{said}; it may be this input's answer or a stale answer to an earlier one, which the monitor "
            "cannot tell apart (docs/monitors.md, \"Transport skew\")")


__all__ = ["DEFAULT_SKEW_S", "EarlyOutputs", "early_reason", "parse_skew"]
