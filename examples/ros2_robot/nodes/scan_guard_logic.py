"""What the scan guard decides from one laser scan (``nodes/scan_guard.py``
runs it on every ``sensor_msgs/LaserScan``; the property tests call
:func:`step`).  Contract: ``ScanGuard`` in ``contracts/robot.rcl``."""

#: m: a beam nearer than this stops the robot
STOP_DISTANCE = 0.5


def step(ranges):
    """``ranges``: the scan's beams (m, at least one, each 0 to 30 m).
    Returns ``{"stop": whether the nearest beam is nearer than STOP_DISTANCE}``."""
    return {"stop": min(ranges) < STOP_DISTANCE}
