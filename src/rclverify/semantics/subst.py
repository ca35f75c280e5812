"""Term substitution through Z3's C API.

``z3.substitute`` checks in Python that each pair's two terms have the same
sort before it calls ``Z3_substitute``, which checks it again (a mismatch is
a ``Z3Exception`` either way).  The temporal engine substitutes a state's
values into a transition relation tens of thousands of times per check
(:mod:`rclverify.calculus.requirements.deadlock`), where those Python checks cost
more than the substitution: a third of a deadlock search's time.
:func:`substitute` makes the same call without them, so the term is the
one ``z3.substitute`` gives.
"""
from __future__ import annotations

from typing import Sequence

import z3


def substitute(e: z3.ExprRef, pairs: Sequence[tuple[z3.ExprRef, z3.ExprRef]]) -> z3.ExprRef:
    """``e`` with each ``from`` of ``pairs`` (``(from, to)``) replaced by its
    ``to``, simultaneously: ``z3.substitute(e, *pairs)``.  Raises
    ``z3.Z3Exception`` when a pair's sorts differ (Z3's own check)."""
    if not pairs:
        return e
    n = len(pairs)
    src = (z3.Ast * n)(*[a.as_ast() for a, _ in pairs])
    dst = (z3.Ast * n)(*[b.as_ast() for _, b in pairs])
    return z3.z3._to_expr_ref(z3.Z3_substitute(e.ctx_ref(), e.as_ast(), n, src, dst), e.ctx)


__all__ = ["substitute"]
