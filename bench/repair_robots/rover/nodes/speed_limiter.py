"""SpeedLimiter's logic: the requested speed, capped."""

MAX_SPEED = 1.5  # m/s


def step(request):
    """``request``: the requested speed (m/s).  Returns ``{"cmd": the speed to drive}``."""
    cmd = min(request, MAX_SPEED)
    return {"cmd": cmd}
