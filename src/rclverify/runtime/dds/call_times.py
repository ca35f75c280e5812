"""The seconds the call taps of the DDS bus wait (:mod:`.services`): an
answer for its call, a sample for the samples stamped before it, an
endpoint before it is said not judged, the endpoints last read before a
sample's stamp.
"""
from __future__ import annotations

#: seconds an answer waits for its request (or goal) to be heard
EARLY_S = 2.0
#: seconds a sample waits after its source stamp, so that samples are taken in the stamps' order
SETTLE_S = 0.3
#: seconds after its receipt a sample is taken whatever its stamp says (a writer whose clock runs ahead)
LATE_S = 1.0
#: seconds an endpoint goes unheard with contents before it is said not judged (the graph's reading of a node
#: that just appeared may list its service before its event publisher)
ENDPOINT_GRACE_S = 1.5
#: seconds before a sample's stamp the endpoints last read still count for it (the graph is read each 0.5 s and a
#: sample is taken 0.3 s after its stamp or later: an endpoint that left meanwhile was there when it was written)
RECENT_S = 1.0

__all__ = ["EARLY_S", "ENDPOINT_GRACE_S", "LATE_S", "RECENT_S", "SETTLE_S"]
