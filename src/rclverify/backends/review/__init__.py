"""The ``review`` backend: a code review recorded as evidence (paper:
Localisation node, shared/reference lines 1307-1317).

Modules: :mod:`.record` (the checklist generated from the guarantees, the
record format and its validation), :mod:`.backend` (:class:`ReviewBackend`),
``templates/record.yaml.j2`` (the blank record ``rclverify review NODE`` writes).
"""
from typing import Any

__all__ = ["ReviewBackend"]


def __getattr__(name: str) -> Any:
    """``ReviewBackend`` loaded on first use (PEP 562): the report enters the package only for
    :mod:`.payload` (the evidence payload)."""
    if name == "ReviewBackend":
        from rclverify.backends.review.backend import ReviewBackend  # deferred: optional or conditional (inside a block)
        return ReviewBackend
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
