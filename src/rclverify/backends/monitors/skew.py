"""Transport skew: how far apart two messages may be stamped in the other order.

A monitor hears each topic over its own connection (a ROS 1 TCPROS link per
publisher, a DDS reader per topic) and stamps an unstamped message when its
callback runs.  A node that answers an input within a millisecond can have
its answer's callback run before the input's: measured on the case study's
live run on a loaded 2-core machine, ``/radiationStatus`` was stamped 0.13 ms
before the ``/r`` reading it answers, in 3 of 6 runs.

The ``skew`` of the mapping (seconds, default :data:`DEFAULT_SKEW_S`; ``skew:
0`` turns it off) bounds that.  What it means for a verdict is the stream
model's (docs/semantics.md, "Transport skew"): an output may answer the
latest question at its stamp or one stamped within the skew after it, and
the engine gives a verdict only where both readings agree
(:mod:`.outcome`); this module only reads the declared value.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, overload

if TYPE_CHECKING:
    from rclverify.core.numeric import np

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


@overload
def within_before(at: float, stamp: float, skew: float) -> bool: ...


@overload
def within_before(at: np.ndarray, stamp: np.ndarray, skew: float) -> np.ndarray: ...


def within_before(at: Any, stamp: Any, skew: float) -> Any:
    """Whether a message stamped ``at`` lies within the transport skew ``skew`` before one stamped ``stamp``
    (all three in one unit): ``stamp - skew <= at <= stamp``, the window the guarantee's early answer
    (closing.py ``_early``) and the deadline rule (:mod:`.deadline_skew`) read.  ``at`` and ``stamp`` may be
    numpy arrays (the batch path's columns, float64 as the doubles above): then a boolean array, element by
    element (NaN is never within)."""
    return (stamp - skew <= at) & (at <= stamp)


__all__ = ["DEFAULT_SKEW_S", "parse_skew", "within_before"]
