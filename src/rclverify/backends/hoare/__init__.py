"""The ``hoare`` backend: node guarantees as Hoare triples over an imperative
model of the node, discharged with Z3 (paper: Radiation Sensor verification,
shared/reference lines 1477-1541; appendix B, 1984-).

Modules: :mod:`.lang` (language: AST, parser, printer; grammar ``imp.lark``),
:mod:`.check` (static checking), :mod:`.wp` (weakest preconditions),
:mod:`.obligations` (guarantee -> triples), :mod:`.solve` (Z3 checks,
counterexamples), :mod:`.outline` (proof outlines), :mod:`.backend`
(:class:`HoareBackend`).
"""
from rclverify.backends.hoare.backend import HoareBackend

__all__ = ["HoareBackend"]
