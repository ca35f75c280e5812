"""When the battery watcher sends the robot home (``nodes/battery_watcher.py``
runs it on every ``sensor_msgs/BatteryState``; the property tests call
:func:`step`).  Contract: ``BatteryWatcher`` in ``contracts/robot.rcl``.

``BatteryState.percentage`` is a ``float32``: the reading 20 % arrives as
0.20000000298..., the float32 nearest 0.2, which is above the double 0.2.
The threshold is therefore compared at the field's width (docs/semantics.md,
"Widths"): ``msg.percentage <= 0.2`` would miss it.
"""
import numpy

#: the charge (a fraction) at which the robot goes home, as the float32 field carries it
LOW = float(numpy.float32(0.2))


def step(percentage):
    """``percentage``: the charge, 0 to 1.  Returns ``{"go_home": whether it is LOW or less}``."""
    return {"go_home": percentage <= LOW}
