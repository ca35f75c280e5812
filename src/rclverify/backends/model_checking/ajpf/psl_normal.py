"""AJPF properties (:mod:`.psl`) in negation normal form and simplified:
:func:`negate` (``~`` only on propositions), :func:`nnf`,
:func:`simplify` (constants folded, duplicates dropped) and
:func:`constant_value` (a property true or false whatever the agent does,
by a truth table over its propositions).  Re-exported by :mod:`.psl`.
"""
from __future__ import annotations

from rclverify.backends.model_checking.ajpf.psl_ast import (
    FALSE, TRUE, Always, And, Const, Eventually, Formula, Implies, Modal, Not, Or, Percept, Release, Until)


#: the propositions of a formula: what a negation stands next to
ATOMS = (Modal, Percept, Const)


def negate(f: Formula) -> Formula:
    """The negation of ``f`` in negation normal form (``~`` only on propositions).

    LTL dualities: ``~[]p = <>~p``, ``~<>p = []~p``, ``~(p U q) = ~p R ~q``,
    ``~(p R q) = ~p U ~q``; De Morgan for ``&``/``||``; ``~(p -> q) = p & ~q``.
    """
    if isinstance(f, Const):
        return Const(not f.value)
    if isinstance(f, (Modal, Percept)):
        return Not(f)
    if isinstance(f, Not):
        return nnf(f.operand)
    if isinstance(f, And):
        return Or(tuple(negate(p) for p in f.parts))
    if isinstance(f, Or):
        return And(tuple(negate(p) for p in f.parts))
    if isinstance(f, Implies):
        return And((nnf(f.left), negate(f.right)))
    if isinstance(f, Always):
        return Eventually(negate(f.operand))
    if isinstance(f, Eventually):
        return Always(negate(f.operand))
    if isinstance(f, Until):
        return Release(negate(f.left), negate(f.right))
    if isinstance(f, Release):
        return Until(negate(f.left), negate(f.right))
    raise TypeError(f"not a PSL formula: {f!r}")


def nnf(f: Formula) -> Formula:
    """``f`` with every negation pushed down to a proposition (see :func:`negate`)."""
    if isinstance(f, ATOMS):
        return f
    if isinstance(f, Not):
        return negate(f.operand)
    if isinstance(f, And):
        return And(tuple(nnf(p) for p in f.parts))
    if isinstance(f, Or):
        return Or(tuple(nnf(p) for p in f.parts))
    if isinstance(f, Implies):
        return Implies(nnf(f.left), nnf(f.right))
    if isinstance(f, Always):
        return Always(nnf(f.operand))
    if isinstance(f, Eventually):
        return Eventually(nnf(f.operand))
    if isinstance(f, Until):
        return Until(nnf(f.left), nnf(f.right))
    if isinstance(f, Release):
        return Release(nnf(f.left), nnf(f.right))
    raise TypeError(f"not a PSL formula: {f!r}")


def _dedupe(parts: list[Formula]) -> tuple[Formula, ...]:
    seen: list[Formula] = []
    for p in parts:
        if p not in seen:
            seen.append(p)
    return tuple(seen)


def simplify(f: Formula) -> Formula:
    """Negation normal form plus constant folding and flattening.

    ``T``/``F`` are folded through every connective (``F -> p`` is ``T``,
    ``T -> p`` is ``p``, ``[] T`` is ``T`` ...), nested ``&``/``||`` are
    flattened and repeated operands dropped (first occurrence kept, so the
    order of the input is preserved).  The result is equivalent to ``f``.
    """
    return _simp(nnf(f))


#: Most opaque atoms :func:`constant_value` enumerates (2**12 assignments).
MAX_TRUTH_TABLE_ATOMS = 12


def constant_value(f: Formula) -> bool | None:
    """``True``/``False`` when ``f`` is a constant whatever the agent does,
    ``None`` when it is not (or not decided).

    Decided after :func:`simplify` (``~T``, ``T & T``, ``F || F`` are
    constants), then by a truth table in which every proposition and every
    temporal subformula is an opaque atom: a formula true (false) under
    every assignment is valid (unsatisfiable) in LTL too, e.g.
    ``B(ag, a) || ~B(ag, a)``.  With more than
    :data:`MAX_TRUTH_TABLE_ATOMS` opaque atoms only the simplification
    decides.
    """
    g = simplify(f)
    if isinstance(g, Const):
        return g.value
    as_written = _table_value(f)  # before negation normal form: ~<> p and <> p share their atom
    return as_written if as_written is not None else _table_value(g)


def _table_value(g: Formula) -> bool | None:
    """The constant value of ``g`` by truth table over its opaque atoms, if any (see :func:`constant_value`)."""
    atoms: list[Formula] = []

    def opaque(h: Formula) -> None:
        if isinstance(h, (Modal, Percept, Always, Eventually, Until, Release)):
            if h not in atoms:
                atoms.append(h)
        elif isinstance(h, Not):
            opaque(h.operand)
        elif isinstance(h, (And, Or)):
            for p in h.parts:
                opaque(p)
        elif isinstance(h, Implies):
            opaque(h.left)
            opaque(h.right)

    opaque(g)
    if len(atoms) > MAX_TRUTH_TABLE_ATOMS:
        return None

    def value(h: Formula, v: dict[Formula, bool]) -> bool:
        if isinstance(h, Const):
            return h.value
        if h in v:
            return v[h]
        if isinstance(h, Not):
            return not value(h.operand, v)
        if isinstance(h, And):
            return all(value(p, v) for p in h.parts)
        if isinstance(h, Or):
            return any(value(p, v) for p in h.parts)
        assert isinstance(h, Implies)
        return not value(h.left, v) or value(h.right, v)

    seen = set()
    for bits in range(1 << len(atoms)):
        seen.add(value(g, {a: bool(bits >> k & 1) for k, a in enumerate(atoms)}))
        if len(seen) == 2:
            return None
    return seen.pop()


def _simp(f: Formula) -> Formula:
    if isinstance(f, (Modal, Percept, Const, Not)):
        return f
    if isinstance(f, (And, Or)):
        is_and = isinstance(f, And)
        unit, zero = (TRUE, FALSE) if is_and else (FALSE, TRUE)
        flat: list[Formula] = []
        for p in f.parts:
            q = _simp(p)
            if q == zero:
                return zero
            if q == unit:
                continue
            if isinstance(q, type(f)):
                flat.extend(q.parts)
            else:
                flat.append(q)
        parts = _dedupe(flat)
        if not parts:
            return unit
        if len(parts) == 1:
            return parts[0]
        return And(parts) if is_and else Or(parts)
    if isinstance(f, Implies):
        left, right = _simp(f.left), _simp(f.right)
        if left == FALSE or right == TRUE:
            return TRUE
        if left == TRUE:
            return right
        if right == FALSE:
            return _simp(negate(left))
        return Implies(left, right)
    if isinstance(f, (Always, Eventually)):
        op = _simp(f.operand)
        if isinstance(op, Const):
            return op
        if isinstance(op, type(f)):  # [] [] p == [] p ; <> <> p == <> p
            return op
        return type(f)(op)
    if isinstance(f, (Until, Release)):
        left, right = _simp(f.left), _simp(f.right)
        if isinstance(f, Until) and right in (TRUE, FALSE):
            return right
        if isinstance(f, Release) and right in (TRUE, FALSE):
            return right
        return type(f)(left, right)
    raise TypeError(f"not a PSL formula: {f!r}")
