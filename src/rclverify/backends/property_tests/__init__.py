"""The ``property_tests`` backend: Python implementations of nodes tested with
Hypothesis against their contracts, every example's outputs checked by Z3
(docs/property-tests.md).

Modules: :mod:`.strategies` (input strategies from RCL types and the
assumption), :mod:`.harness` (one guarantee's Hypothesis run; also what the
generated pytest files call), :mod:`.backend` (:class:`PropertyTestsBackend`).
"""
from .backend import PropertyTestsBackend

__all__ = ["PropertyTestsBackend"]
