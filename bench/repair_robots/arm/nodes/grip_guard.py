"""GripGuard's logic: a grip force is safe within the band."""

MIN_FORCE = 5.0  # N
MAX_FORCE = 40.0  # N


def step(force):
    """``force``: the grip force (N).  Returns ``{"safe": whether it is within the band}``."""
    safe = MIN_FORCE <= force and force <= MAX_FORCE
    return {"safe": safe}
