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
from rclverify.backends.dafny.backend import DafnyBackend

__all__ = ["DafnyBackend"]
