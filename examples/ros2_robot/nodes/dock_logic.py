"""How the dock server drives onto the charging dock (``nodes/dock.py`` runs
:func:`step` for each goal, publishing each tick's feedback; the property
tests call it without).  Contract: ``Dock`` in ``contracts/robot.rcl``."""

#: m the robot drives per control tick
STEP = 0.25
#: m: the robot is on the dock within this distance of it
TOLERANCE = 0.05


def _no_feedback(remaining):
    """Where no one listens to the ticks (the property tests)."""


def step(distance, feedback=_no_feedback):
    """Drive from ``distance`` (m, the goal) to the dock: ``feedback(m)`` is
    called with the distance left at the start and after each tick.  Returns
    ``{"left": the last feedback's distance (m), "final": the result's
    distance (m)}``."""
    remaining = distance
    feedback(remaining)
    while remaining > TOLERANCE:
        remaining = max(0.0, remaining - STEP)
        feedback(remaining)
    final = remaining
    return {"left": remaining, "final": final}
