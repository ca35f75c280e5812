"""JointCheck's logic: every joint within its limit."""

LIMIT = 3.0  # rad


def step(positions):
    """``positions``: the joints' positions (rad).  Returns ``{"ok": whether none is past LIMIT}``."""
    worst = max(positions, default=0.0)
    return {"ok": worst <= LIMIT}
