"""What a live run says of each node while it runs: the status line's
parts (the answers counted and their bound, docs/statistics.md; the
smallest margins, docs/semantics.md, "Margins") and the warning of a margin
under ``--warn-margin`` before a violation (docs/monitors.md).

The counts and margins are the engine's (each judged answer's space margin,
:mod:`rclverify.semantics.robustness`); this module only reads them.
"""
from __future__ import annotations

import math
import threading
from typing import Callable, Iterable

from rclverify.backends.monitors.check import NodeResult, Verdict
from rclverify.backends.monitors.engine import NodeMonitor
from rclverify.records.statistics import trivial_or_exact


class LowMargins:
    """Warns, one line each, of every guarantee whose smallest margin a
    satisfied answer has just lowered below ``limit`` (the guarantee's
    units): a new smallest only, so a guarantee hovering low is not repeated.
    ``monitors`` are the live engine's node monitors (margins on); ``warn``
    takes each line (``None``: computed, not said)."""

    def __init__(self, monitors: Iterable[NodeMonitor], limit: float, warn: Callable[[str], None] | None) -> None:
        self.limit, self.warn = limit, warn
        self._by_node = {m.node.name: m for m in monitors}
        self._warned: dict[tuple[str, int], float] = {}

    def heard(self, v: Verdict) -> None:
        """Look at verdict ``v`` (any verdict: only a satisfied one under the limit can warn)."""
        if v.verdict != "satisfied" or v.margin is None or v.margin >= self.limit:
            return
        mon = self._by_node.get(v.node)
        if mon is None:
            return
        for k, gm in sorted(mon.result.margins.items()):
            if gm.event != v.event or not math.isfinite(gm.value) or gm.value >= self.limit \
                    or gm.value >= self._warned.get((v.node, k), math.inf):
                continue
            self._warned[(v.node, k)] = gm.value
            unit = f" {gm.unit}" if gm.unit else ""
            if self.warn is not None:
                self.warn(f"rclverify monitor: warning: {v.node} guarantee {k} held with margin {gm.value:g}{unit} "
                          f"({gm.atom}), below --warn-margin {self.limit:g}, at t = {v.time:.6f} s ({v.where})")


def least_margins(res: NodeResult) -> str:
    """``; least margin g1 0.04 m, g2 0.5``: each guarantee's smallest space
    margin so far (docs/semantics.md, "Margins"), ``""`` without margins or
    before the first; an infinite one (no distance) is left out."""
    shown = [f"g{k} {m.value:g}" + (f" {m.unit}" if m.unit else "") for k, m in sorted(res.margins.items())
             if m.answers and math.isfinite(m.value)]
    return f"; least margin {', '.join(shown)}" if shown else ""


#: set once :func:`warm_bounds`'s thread has loaded the bound's library (or found it missing)
_READY = threading.Event()


def running_bound(res: NodeResult, wait: bool = True) -> str:
    """``; 40 answer(s) counted, 95 % bound 0.0722 per answer``: the one-sided
    Clopper-Pearson bound on the probability that an answer violates the
    contract, from the counts so far (undecided answers count as
    violations; docs/statistics.md); ``""`` before the first answer.  With
    ``wait`` false (a running live monitor's status line) and the bound's
    library not yet loaded by :func:`warm_bounds`: ``; 40 answer(s) counted,
    95 % bound not yet computed (its library is loading)``, at once."""
    c = res.counts
    n = c.get("satisfied", 0) + c.get("violated", 0) + c.get("inconclusive", 0)
    if not n:
        return ""
    if not wait and not _READY.is_set():
        return f"; {n} answer(s) counted, 95 % bound not yet computed (its library is loading)"
    bound, why = trivial_or_exact(n - c.get('satisfied', 0), n, 0.95)
    return f"; {n} answer(s) counted, 95 % bound {bound:.3g} per answer" + (f" ({why})" if why else "")


def warm_bounds() -> threading.Thread:
    """Start loading, in a daemon thread (``rclverify-warm``), the library :func:`running_bound` computes
    its exact bound with (scipy's, about a second of CPU): a live run calls it once it has started
    (after its last child process is started: the load sets ``OPENBLAS_NUM_THREADS`` for its duration,
    :mod:`rclverify.core.numeric`), so the status line a stop prints never waits for the load and a
    stop ends the run within a second (docs/monitors.md, "Stopping"); until it has, a status line asked
    not to wait says the bound is loading (:func:`running_bound`).  Without the ``stats`` extra the
    thread ends at once (the line then names the extra).  Returns the thread, started."""
    def load() -> None:
        try:
            from rclverify.core.numeric import scipy_special  # deferred: start-up (loads numpy and scipy, in this thread)
            scipy_special()
        except ImportError:
            pass
        finally:
            _READY.set()
    t = threading.Thread(target=load, name="rclverify-warm", daemon=True)
    t.start()
    return t


__all__ = ["LowMargins", "least_margins", "running_bound", "warm_bounds"]
