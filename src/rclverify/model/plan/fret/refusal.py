"""A FRET requirement that cannot be imported, and why (docs/requirements.md,
"Requirements from FRET"): raised by every reader of :mod:`rclverify.model.plan.fret`
and reported at the requirement's ``reqid``."""
from __future__ import annotations


class Refusal(Exception):
    """A requirement that cannot be imported: ``reason`` (what is in the
    way) and ``fix`` (what would make it importable)."""

    def __init__(self, reason: str, fix: str) -> None:
        super().__init__(f"{reason}; {fix}")
        self.reason, self.fix = reason, fix


__all__ = ["Refusal"]
