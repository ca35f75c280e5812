"""The distinct subterms of Z3 formulas, each once.

Z3 shares equal subterms (hash-consing), so a formula is a DAG that a tree
walk would visit many times over; the walk here keeps the ids it has seen.
Quantifier bodies are walked too (their bound variables, de Bruijn indices,
are not applications).  Used wherever a check reads what formulas mention:
their numerals, their uninterpreted symbols, their free constants.
"""
from __future__ import annotations

from typing import Iterable, Iterator

import z3


def subterms(formulas: Iterable[z3.ExprRef]) -> Iterator[z3.ExprRef]:
    """Every distinct subterm of ``formulas`` (the formulas themselves
    included), each once, a term before its arguments (depth first, the last
    argument first); a quantifier is followed by its body.  Never raises."""
    seen: set[int] = set()
    todo = list(formulas)
    while todo:
        e = todo.pop()
        if e.get_id() in seen:
            continue
        seen.add(e.get_id())
        yield e
        if z3.is_quantifier(e):
            todo.append(e.body())
        elif z3.is_app(e):
            todo.extend(e.children())
