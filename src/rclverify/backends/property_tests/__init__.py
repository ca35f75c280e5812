"""The ``property_tests`` backend: Python implementations of nodes tested with
Hypothesis against their contracts, every example's outputs checked by Z3
(docs/property-tests.md).

Modules: :mod:`.strategies` (input strategies from RCL types and the
assumption, whose bounds :mod:`.bounds` reads; the thresholds every comparison puts on an input,
:mod:`.thresholds`), :mod:`.harness` (one guarantee's Hypothesis run; also what the
generated pytest files call), :mod:`.slips` (the implementation line with the
slip, a correction weighed on the :mod:`.neighbours` examples; :mod:`.cause`
the line that computed the value, its fallback), :mod:`.backend`
(:class:`PropertyTestsBackend`).
"""
from typing import Any

__all__ = ["PropertyTestsBackend"]


def __getattr__(name: str) -> Any:
    """``PropertyTestsBackend`` loaded on first use (PEP 562): the package is
    also entered for :mod:`.closure` by every ``doit`` start (app/tasks.py, the
    implementation's import closure), which must not pay for importing
    Hypothesis (about 0.3 s of a no-op run's 0.46 s)."""
    if name == "PropertyTestsBackend":
        from rclverify.backends.property_tests.backend import PropertyTestsBackend  # deferred: optional or conditional (inside a block)
        return PropertyTestsBackend
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
