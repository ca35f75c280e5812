"""RateMeter's logic: a count over the time it took."""


def step(count, dt):
    """``count``: events; ``dt``: the time they took (s).  Returns ``{"rate": events per second}``."""
    if dt == 0:
        return {"rate": 0.0}
    return {"rate": count / dt}
