"""Refinement of timed guarantees: a slower deadline never refines a faster one.

A guarantee ``G(phi) triggered by in.x within d`` promises an answer to every
message on ``in.x`` within ``d`` (rule D1, docs/rcl-language.md, "Services,
actions and deadlines"; the stream model of docs/semantics.md).  Contract B
may replace contract A (paper lines 1667-1700) only if every such promise
of A is kept by B: for each timed guarantee of A, the guarantees of B
triggered by the same input with a deadline no longer than A's (a
``triggered by`` without ``within`` in A accepts any of B's answers to that
input) must imply ``phi`` wherever A's assumption holds:

    ``A_A and /\\ { phi_B : trigger_B = x, d_B <= d_A }  =>  phi_A``

An untimed guarantee of B promises an answer eventually, never within a
bound, so it does not count.  When no guarantee of B qualifies, the side is
refuted without a solver ("B promises no answer to in.x within 500 ms").

:func:`timing_side` decides it with Z3 (:func:`rclverify.semantics.query.prove`)
and returns a :class:`~.refinement.SideResult`-shaped tuple, or ``None`` when
A has no triggered guarantee (nothing to keep).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping, Sequence

import z3

from rclverify.semantics.encode import Encoder
from rclverify.semantics.query import DEFAULT_TIMEOUT_MS, QueryResult, prove
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.timing import seconds
from rclverify.lang.types import CheckedNode


@dataclass(frozen=True)
class TimedPromise:
    """One triggered guarantee: its 1-based index, trigger input name, deadline
    in seconds (``None``: no ``within``) and formula."""

    index: int
    trigger: str
    bound: Fraction | None
    formula: ast.Expr


def promises(node: CheckedNode) -> list[TimedPromise]:
    """The triggered guarantees of ``node``, in order."""
    out = []
    for k, cl in enumerate(node.node.guarantees, 1):
        if cl.trigger is not None:
            out.append(TimedPromise(k, cl.trigger.name, seconds(cl.deadline) if cl.deadline is not None else None,
                                    cl.formula))
    return out


def keeps(b: TimedPromise, a: TimedPromise) -> bool:
    """Does B's promise answer A's input at least as fast?  Same trigger, and
    B's deadline no longer than A's (A without ``within``: any B answer)."""
    if b.trigger != a.trigger:
        return False
    if a.bound is None:
        return True
    return b.bound is not None and b.bound <= a.bound


def _text(p: TimedPromise) -> str:
    within = f" within {float(p.bound) * 1000:g} ms" if p.bound is not None else ""
    return f"{expr_to_rcl(p.formula)} triggered by in.{p.trigger}{within}"


def timing_side(a: CheckedNode, b: CheckedNode, enc: Encoder, shared: Mapping[str, z3.AstRef],
                hyps: Sequence[z3.BoolRef], assumption: z3.BoolRef, *,
                timeout_ms: int = DEFAULT_TIMEOUT_MS) -> tuple[str, str, QueryResult | None, str] | None:
    """The timing side of "B refines A": ``(statement, status, query, reason)``.

    ``enc``/``shared`` encode both nodes' formulas over the same symbols (as
    :func:`~.refinement.check_refinement` does); ``hyps`` the environment
    facts and conditions; ``assumption`` A's assumption encoded.  ``status``
    is ``proved``, ``refuted`` or ``inconclusive``; ``query`` the Z3 query of
    the last promise decided (``None`` when a promise had no candidate in
    B); ``reason`` why it was refuted without a solver.  ``None`` when A has
    no triggered guarantee.  Raises :class:`~rclverify.semantics.encode.EncodingError`
    as the encoder does."""
    mine = promises(a)
    if not mine:
        return None
    theirs = promises(b)
    statements, last = [], None
    for p in mine:
        kept = [q for q in theirs if keeps(q, p)]
        stmt = (f"A_{a.name} and {' and '.join(_text(q) for q in kept) or 'nothing'} -> {_text(p)}")
        statements.append(stmt)
        if not kept:
            slower = [q for q in theirs if q.trigger == p.trigger]
            why = (f"{b.name} answers in.{p.trigger} only within "
                   f"{', '.join(f'{float(q.bound) * 1000:g} ms' if q.bound is not None else 'no bound' for q in slower)}"
                   f", slower than {a.name}'s guarantee {p.index} ({_text(p)})" if slower else
                   f"{b.name} promises no answer to in.{p.trigger}, which {a.name}'s guarantee {p.index} does "
                   f"({_text(p)})")
            return stmt, "refuted", None, why
        goal = enc.formula(p.formula, a, dict(shared))
        premises = [assumption, *hyps, *(enc.formula(q.formula, b, dict(shared)) for q in kept)]
        q = prove(goal, premises, enc, timeout_ms=timeout_ms, deterministic=True,
                  comment=f"refinement, timing side: guarantee {p.index} of {a.name} "
                          f"(triggered by in.{p.trigger}) kept by {b.name}'s answers as fast")
        last = q
        if q.status != "proved":
            return stmt, q.status, q, q.reason
    return "; ".join(statements), "proved", last, ""


__all__ = ["TimedPromise", "keeps", "promises", "timing_side"]
