"""ModeServer's logic: the speed a requested mode allows."""

CAREFUL = 2


def step(mode):
    """``mode``: the requested mode (0 to 3).  Returns ``{"speed": m/s}``."""
    if mode == CAREFUL:
        return {"speed": 0.5}
    return {"speed": 1.0}
