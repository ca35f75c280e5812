"""A ROS 2 bag of one `sensor_msgs/LaserScan` on /scan (float32 ranges) and the
node's one answer 10 ms later, for the tests of sequences and widths."""
from __future__ import annotations

from pathlib import Path
from typing import Any


def scan_bag(path: Path, ranges: list[float], answer_topic: str, answer_type: str, answer: Any) -> Path:
    """Write the bag at ``path``: the scan at 1 s, then ``answer`` (the ``data`` of a
    ``std_msgs/msg/<answer_type>``) on ``/<answer_topic>`` at 1.01 s; returns ``path``."""
    import numpy as np
    from rosbags.rosbag2 import Writer

    from rclverify.traces.bag import typestore
    s = typestore([])
    t = s.types
    header = t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="")
    scan = t["sensor_msgs/msg/LaserScan"](header=header, angle_min=0.0, angle_max=1.0, angle_increment=0.1,
                                          time_increment=0.0, scan_time=0.1, range_min=0.1, range_max=30.0,
                                          ranges=np.array(ranges, dtype=np.float32),
                                          intensities=np.array([], dtype=np.float32))
    kind = f"std_msgs/msg/{answer_type}"
    with Writer(path, version=9) as w:
        a = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=s)
        b = w.add_connection(f"/{answer_topic}", kind, typestore=s)
        w.write(a, 1_000_000_000, s.serialize_cdr(scan, "sensor_msgs/msg/LaserScan"))
        w.write(b, 1_010_000_000, s.serialize_cdr(t[kind](data=answer), kind))
    return path
