"""A message's time on the robot's clock, and the order of a run.

Every path that judges messages (the live sources, the bags and logs they
record, the offline readers) places a message by the time the robot acted
(docs/semantics.md, "Event time"):

* its ``header.stamp`` when it has one (the robot's own statement of when
  the data was taken; a node that copies its input's stamp into its answer
  pairs the two exactly);
* else the **source timestamp** its publisher's middleware wrote when the
  message was published (rmw's ``message_info.source_timestamp`` on the
  rclpy source, the DDS sample's ``source_timestamp`` on Cyclone DDS, the
  time the live monitor recorded in its bag and log);
* else the time the monitor received it (ROS 1, which carries no source
  time; a log with nothing else).

Two messages with equal stamps are ordered by their source times, then by
the order heard: an answer that copies its question's stamp was published
after that question, whichever of the two reached the monitor first.

:func:`event_ns` (:func:`event_s` in seconds) is the rule for one live
sample; :func:`order_key` the key of the one reorder buffer
(:mod:`.reorder`), which every path that orders a run calls.  A message is released for judging only once
no message that could precede it can still arrive: the **watermark** is the
monitor's clock less the lateness bound (``--reorder-window``, seconds), the
event-time watermark of stream processors (Akidau et al., "The Dataflow
Model", VLDB 2015; Basin, Klaedtke and Zalinescu, "Runtime Verification
over Out-of-order Streams", ACM TOCL 2020).  A message heard after the
watermark passed its time is **late**: counted, with the largest lateness.
"""
from __future__ import annotations

#: a source time more than this ahead of its receipt (ns) is not the monitor's clock: the receipt stands in
AHEAD_NS = 1_000_000_000


def event_ns(source_ns: int, received_ns: int) -> tuple[int, bool]:
    """``(time, from_source)``: the sample's time on the robot's clock (ns
    since the epoch) and whether it is the publisher's source timestamp.

    ``source_ns`` is the middleware's source timestamp (0 when it gave
    none), ``received_ns`` when the monitor took the sample.  A source time
    later than the receipt by more than :data:`AHEAD_NS` (a publisher whose
    clock runs ahead of the monitor's) cannot be placed on the monitor's
    watermark, so the receipt stands in and ``from_source`` is false; one
    earlier than the receipt is the normal case (the transport's delay)."""
    if source_ns > 0 and source_ns - received_ns <= AHEAD_NS:
        return source_ns, True
    return received_ns, False


def event_s(source: float, received: float) -> float:
    """:func:`event_ns` in seconds: the sample's time on the robot's clock
    (s), its source time ``source`` (s, 0 when none) unless that is more
    than :data:`AHEAD_NS` ahead of its receipt ``received`` (s)."""
    return source if source > 0 and (source - received) * 1e9 <= AHEAD_NS else received


def order_key(stamp: float, source: float, seq: int) -> tuple[float, float, int]:
    """The reorder buffers' key: a message's time on the run's clock
    (``stamp``, s: its header stamp, else its event time), then its source
    time (``source``, s: equal stamps in the order they were published),
    then the order heard (``seq``)."""
    return (stamp, source, seq)


__all__ = ["AHEAD_NS", "event_ns", "event_s", "order_key"]
