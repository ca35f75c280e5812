"""Odometer's logic: the ticks of both wheels added."""


def step(left, right):
    """``left``, ``right``: each wheel's ticks.  Returns ``{"ticks": their sum}``."""
    ticks = left + right
    return {"ticks": ticks}
