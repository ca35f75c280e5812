"""Conjunctions and disjunctions of many Z3 terms, built without z3.py's coercion.

``z3.And(*terms)`` and ``z3.Or(*terms)`` coerce every argument before
making the term: for each one a sort object is made, compared with the
others' and cast, about a dozen calls through the C API an argument (about
250 microseconds for 20 Boolean terms).  The transition systems of the
temporal checks build such connectives by the thousand (a lasso search asks
about every loop of every length: :mod:`rclverify.calculus.requirements.tsys`),
and the coercion was the largest cost of their checks after the solver
(about a sixth of the warehouse example's whole run).

:func:`conj` and :func:`disj` take the same arguments and return the same
term.  When every argument is a ``z3.BoolRef`` of one context (the case of
every call in rclverify), nothing needs coercing, and the term is made by
one call of ``Z3_mk_and`` / ``Z3_mk_or`` on the arguments as they are,
which is what ``z3.And`` / ``z3.Or`` call after coercing them: Z3 shares
equal terms, so the result is the very term (the same ``get_id()``;
``tests/semantics/test_connectives.py``).  Any other arguments (none, a Python
``bool``, a probe, a context, a list, terms of two contexts) are handed to
``z3.And`` / ``z3.Or`` unchanged, so they give what those give and raise what
those raise.  A ``BoolRef`` whose sort is not Boolean (a ``z3.Lambda``)
makes Z3 raise ``z3.Z3Exception`` (a sort mismatch), as ``z3.And`` does.
"""
from __future__ import annotations

from typing import Any, Callable

import z3
from z3 import z3core

__all__ = ["conj", "disj"]


def _direct(make: Callable[..., Any], args: tuple[Any, ...]) -> z3.BoolRef | None:
    """The term ``make`` (``Z3_mk_and``/``Z3_mk_or``) gives ``args`` when they
    are ``BoolRef`` terms of one context, else ``None``."""
    if not args or not isinstance(args[0], z3.BoolRef):
        return None
    ctx = args[0].ctx
    for a in args:
        if not isinstance(a, z3.BoolRef) or a.ctx is not ctx:
            return None
    n = len(args)
    return z3.BoolRef(make(ctx.ref(), n, (z3.Ast * n)(*[a.as_ast() for a in args])), ctx)


def conj(*args: Any) -> z3.BoolRef:
    """``z3.And(*args)``: the same term, made without coercing Boolean
    terms of one context (module docstring).  Raises what ``z3.And`` raises."""
    got = _direct(z3core.Z3_mk_and, args)
    return z3.And(*args) if got is None else got


def disj(*args: Any) -> z3.BoolRef:
    """``z3.Or(*args)``: the same term, made without coercing Boolean
    terms of one context (module docstring).  Raises what ``z3.Or`` raises."""
    got = _direct(z3core.Z3_mk_or, args)
    return z3.Or(*args) if got is None else got
