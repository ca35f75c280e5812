"""semantics (its place among the layers: docs/architecture.md): what an RCL formula means.

RCL values (``values``), the reference evaluator and its fast paths
(closures, straight-line code), exact / IEEE-754 / tolerant judging, and
the SMT encoding with Z3 (``encode``, ``decide``, ``query``).  Imports
``lang`` and below.
"""
