"""The end of a live run, carried in the bag its monitor recorded.

A live run's log ends with the lines its monitor wrote until it stopped
(verdicts, deadline verdicts, call lines), each at the time of the
monitor's clock that wrote it: read offline, those lines move the monitors'
clocks as far as the live clock went, so a question whose horizon the live
clock passed unanswered is closed (``inconclusive``, not ``open``) and a
trigger whose deadline it passed unanswered is ``false``
(:class:`~rclverify.backends.monitors.deadlines.DeadlineMonitor`) on the
log too.  A bag holds the contract's messages only, and ends with its last
message: a question still within its horizon there is ``open`` and a
deadline due after it ``currently_false``, honestly for a bag that does not
say the run went on, but then the bag cannot tell a question the run
stopped before from one the live clock passed.

Every bag written by ``rclverify monitor --live --record`` (either source,
whatever its contracts) therefore carries one message, written last, on
:data:`TOPIC` (``/rclverify/run_end``), of the standard type :data:`TYPE`
(``builtin_interfaces/msg/Time``): the time the live run's monitors' clock
reached when it stopped (the node monitors' and the deadline checks', the
engine's watermark; s and ns since the epoch, the time line the log's lines
use), stored at that same time (a message of the run's last reorder window
may be stored later: the bag's clock is the later of the two). Any ROS 2
tool reads it (``ros2 bag info``, ``ros2 bag play`` publishes it once);
rclverify's bag readers read it as any message, an event on
``rclverify/run_end`` at the time it carries, which moves every monitor's
clock to the run's end as the log's last lines do, and which no contract
names. A bag without it (any bag not recorded by rclverify, and those
recorded before it was written) ends at its last message, as before.
docs/ros2.md ("The run's end in the bag") gives the decision.
"""
from __future__ import annotations

#: the topic of a recorded bag's end-of-run message (module docstring), without the leading ``/``
TOPIC = "rclverify/run_end"
#: its type: a standard one, read by every ROS 2 tool
TYPE = "builtin_interfaces/msg/Time"


def split_ns(time_ns: int) -> tuple[int, int]:
    """``(sec, nanosec)`` of ``time_ns`` (ns since the epoch, >= 0): the fields of :data:`TYPE`."""
    return time_ns // 1_000_000_000, time_ns % 1_000_000_000


__all__ = ["TOPIC", "TYPE", "split_ns"]
