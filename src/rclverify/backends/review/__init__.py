"""The ``review`` backend: a code review recorded as evidence (paper:
Localisation node, shared/reference lines 1307-1317).

Modules: :mod:`.record` (the checklist generated from the guarantees, the
record format and its validation), :mod:`.backend` (:class:`ReviewBackend`),
``templates/record.yaml.j2`` (the blank record ``rclverify review NODE`` writes).
"""
from rclverify.backends.review.backend import ReviewBackend

__all__ = ["ReviewBackend"]
