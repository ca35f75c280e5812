"""The ``dafny`` backend (paper lines 1667-1762: a node re-specified and
verified in Dafny, showing implementations are interchangeable under the
node's contract).

Modules (the translation of RCL types and formulas to Dafny is
:mod:`rclverify.targets.dafny`): :mod:`.stubgen` (the ``abstract module``
contract stub), :mod:`.runner` (find, identify, run Dafny and read its
output), :mod:`.refute` (a counterexample for a guarantee Dafny could not
prove, or none), :mod:`.backend` (:class:`DafnyBackend`, name ``dafny``, kind
``proof``).
"""
from typing import Any

__all__ = ["DafnyBackend"]


def __getattr__(name: str) -> Any:
    """``DafnyBackend`` loaded on first use (PEP 562): the report enters the package only for
    :mod:`.payload` (the evidence payload)."""
    if name == "DafnyBackend":
        from rclverify.backends.dafny.backend import DafnyBackend  # deferred: optional or conditional (inside a block)
        return DafnyBackend
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
