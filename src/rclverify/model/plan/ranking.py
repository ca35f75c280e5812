"""A liveness requirement's ``ranking:`` and ``invariant:``.

An unbounded ``eventually P`` (or the liveness part of ``F until P``) is
proved only through a ranking function the user supplies
(docs/requirements.md, "Proof by a ranking function")::

    - id: R1
      formal: "eventually Countdown.state.c == 0"
      ranking: "Countdown.state.c"
      invariant: "Countdown.state.c <= 100"     # optional, default TRUE

``ranking`` is an RCL term of type ``INTEGER`` or ``NATURAL`` and
``invariant`` an RCL formula, both over ``Node.in.x``/``Node.out.y``/
``Node.state.v`` as the statement's operands (:mod:`.formal`, with the plan's
declared state variables, :mod:`.state`).  They are read like ``formal:``:
every diagnostic lands on the plan's line and column.

``invariant:`` is also read for every other temporal
statement: it strengthens the k-induction that proves ``always F``, the
response patterns and ``until``'s safety part (docs/requirements.md,
"Proofs a user can finish").

Errors (``E-type``: a ranking term that is not integer-valued;
``E-temporal``: ``ranking:`` on a requirement whose ``formal:`` is not an
unbounded ``eventually``, an ``until`` or an unbounded response, ``invariant:``
on a state requirement; the name and type errors of
:func:`.formal.read_expr`) are located :class:`RclError` diagnostics.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.lang.types import INTEGER, NATURAL, Checked, CheckedNode, Type
from rclverify.model.plan.formal import Formal, Source, parse_formal, read_expr
from rclverify.model.plan.temporal import Temporal


@dataclass(frozen=True)
class Term:
    """A parsed, type-checked integer term: ``expr`` over ``Node.in.x``
    names of the pseudo node ``scope`` (as :class:`.formal.Formal`),
    ``mentions`` the ``(node, prefix, var)`` triples it names."""

    expr: ast.Expr
    scope: CheckedNode
    mentions: tuple[tuple[str, str, str], ...]

    @property
    def nodes(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(n for n, _, _ in self.mentions))


def parse_ranking(src: Source, checked: Checked, what: str,
                  states: Mapping[tuple[str, str], Type] | None = None) -> Term:
    """Parse and type-check a ``ranking:`` term (module docstring).

    Returns a :class:`Term`; raises :class:`RclError` (``E-type`` at the
    term when its type is not ``INTEGER``/``NATURAL``; the located errors of
    :func:`.formal.read_expr`)."""
    expr, scope, mentions, t = read_expr(src, checked, what, states)
    if t not in (INTEGER, NATURAL):
        raise RclError([error(src.loc, f"{what}: a ranking function must be an INTEGER or NATURAL term, "
                                       f"found {t}", "E-type")])
    return Term(expr, scope, mentions)


def is_liveness(t: "Temporal | Formal") -> bool:
    """Whether statement ``t`` is an unbounded ``eventually F``, an ``F
    until G`` or the unbounded response ``always (P -> eventually Q)``: the
    statements a ranking function proves (docs/requirements.md)."""
    if not isinstance(t, Temporal):
        return False
    if t.op == "always" and isinstance(t.args[0], Temporal) and t.args[0].op == "->":
        r = t.args[0].args[1]
        return isinstance(r, Temporal) and r.op == "eventually" and r.bound is None
    return (t.op == "eventually" and t.bound is None) or t.op == "until"


def parse_hints(ranking: Source | None, invariant: Source | None, statement: "Temporal | Formal",
                checked: Checked, rid: str, states: Mapping[tuple[str, str], Type] | None = None
                ) -> tuple[Term | None, Formal | None]:
    """A requirement's ``(ranking, invariant)`` parsed (``None`` where
    absent); ``statement`` is its parsed ``formal:``.  Raises
    :class:`RclError` with every located error: ``E-temporal`` at a
    ``ranking:`` given on a statement that is not liveness (:func:`is_liveness`), else
    the errors of :func:`parse_ranking` and :func:`.formal.parse_formal`.
    An ``invariant:`` is read for every temporal statement (it
    strengthens the induction that proves a safety pattern, and is the
    ranking function's domain for a liveness one), never for a state
    requirement (``E-temporal``)."""
    diags = []
    out: list[Term | Formal | None] = [None, None]
    for k, (src, key) in enumerate(((ranking, "ranking"), (invariant, "invariant"))):
        if src is None:
            continue
        if k == 0 and not is_liveness(statement):
            diags.append(error(src.loc, f"{rid} {key}: a ranking function is read only for a liveness statement "
                                        "(formal: eventually F without a bound, F until G, or always (F -> eventually G))", "E-temporal"))
            continue
        if k == 1 and not isinstance(statement, Temporal):
            diags.append(error(src.loc, f"{rid} {key}: an invariant is read only for a temporal statement (a state "
                                        "requirement is decided over one step, with no induction to strengthen)",
                               "E-temporal"))
            continue
        try:
            out[k] = (parse_ranking(src, checked, f"{rid} ranking", states) if k == 0
                      else parse_formal(src, checked, f"{rid} invariant", states))
        except RclError as exc:
            diags.extend(exc.diagnostics)
    if diags:
        raise RclError(diags)
    return out[0], out[1]  # type: ignore[return-value]
