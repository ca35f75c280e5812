"""Lint for RCL contracts: legal text that authors rarely mean.

``lint(spec)`` returns located warnings (severity ``"warning"``); it never
raises and never changes what a contract means.  The rules:

``W-implication-precedence``
    An operand of ``->`` (or ``<=>``) that is an ``and``/``or`` written
    without parentheses.  RCL's fixed precedence (``<=>``, ``->``, ``or``,
    ``and``, ... loosest first; see ``rcl.lark``) reads ``A and B -> C`` as
    ``(A and B) -> C`` and ``A -> B and C`` as ``A -> (B and C)``.  The paper's
    own contracts show why this deserves a warning: the Radiation Sensor
    guarantee of appendix A (shared/reference lines 1966-1983) reads, as
    printed, as one chain of implications, while its table and prose
    (lines 1290-1304, 1485-1492) mean separate conjuncts.
``W-unused-bound``
    A quantified variable that neither the quantifier's body nor a later
    binding's domain mentions (e.g. the ``x', y'`` of the Agent's third
    guarantee, listing at lines 1143-1171).
``W-unconstrained-output``
    A node output that no guarantee mentions: the contract says nothing
    about it, so no obligation will constrain it.

An input that no assumption or guarantee mentions is *not* reported: inputs
may be passed through or consumed only by the implementation.
"""
from __future__ import annotations

from . import ast
from .errors import Diagnostic, warning
from .walk import free_names, subexpressions

_IMPLICATIONS = ("->", "<=>")
_JUNCTIONS = ("and", "or")


def lint(spec: ast.Spec) -> list[Diagnostic]:
    """All lint warnings of one parsed RCL file, sorted by location.

    ``spec``: a :class:`~rclverify.rcl.ast.Spec` from the parser.
    Returns a list of :class:`~rclverify.rcl.errors.Diagnostic` with
    severity ``"warning"`` and codes ``W-implication-precedence``,
    ``W-unused-bound`` and ``W-unconstrained-output``."""
    diags: list[Diagnostic] = []
    for ctx in spec.contexts:
        for decl in ctx.decls:
            if isinstance(decl, ast.ConstDecl):
                where = f"constant {decl.name}"
                diags += _implication_precedence(decl.value, where)
                diags += _unused_bound(decl.value, where)
    for node in spec.nodes:
        for kind, clauses in (("assumption", node.assumes), ("guarantee", node.guarantees)):
            for i, clause in enumerate(clauses, 1):
                where = f"{kind} {i} of {node.name}"
                diags += _implication_precedence(clause.formula, where)
                diags += _unused_bound(clause.formula, where)
        diags += _unconstrained_outputs(node)
    return sorted(diags, key=lambda d: (d.loc.file, d.loc.line, d.loc.col, d.code))


# ---------------------------------------------------------------------------
# Traversal
# ---------------------------------------------------------------------------

# ---------------------------------------------------------------------------
# Rules
# ---------------------------------------------------------------------------

def _implication_precedence(formula: ast.Expr, where: str) -> list[Diagnostic]:
    diags = []
    for e in subexpressions(formula):
        if not (isinstance(e, ast.Binary) and e.op in _IMPLICATIONS):
            continue
        for side, operand in (("left", e.left), ("right", e.right)):
            if isinstance(operand, ast.Binary) and operand.op in _JUNCTIONS and not operand.parenthesised:
                j, imp = operand.op, e.op
                reading = f"(A {j} B) {imp} C" if side == "left" else f"A {imp} (B {j} C)"
                diags.append(warning(
                    operand.loc,
                    f"{where}: '{imp}' has an unparenthesised '{j}' as its {side} operand; "
                    f"read as {reading}; add parentheses to make it explicit",
                    "W-implication-precedence"))
    return diags


def _unused_bound(formula: ast.Expr, where: str) -> list[Diagnostic]:
    diags = []
    for e in subexpressions(formula):
        if not isinstance(e, ast.Quant):
            continue
        body_free = free_names(e.body)
        for k, b in enumerate(e.bindings):
            for n, name in enumerate(b.names):
                if _used_after(name, e.bindings[k + 1:], body_free):
                    continue
                loc = b.name_locs[n] if n < len(b.name_locs) else b.loc
                diags.append(warning(
                    loc,
                    f"{where}: bound variable {name} of '{e.kind}' is never used in its body",
                    "W-unused-bound"))
    return diags


def _used_after(name: str, later: tuple[ast.Binding, ...], body_free: set[str]) -> bool:
    """Whether ``name`` is referred to by the domains of the later bindings
    of its quantifier or by the body (unless a later binding rebinds it)."""
    for b in later:
        if name in free_names(b.domain):
            return True
        if name in b.names:
            return False
    return name in body_free


def _mentions(formula: ast.Expr) -> set[tuple[str | None, str]]:
    """(prefix, name) of the I/O references in ``formula``; unprefixed
    names only when free (not a bound variable)."""
    refs: set[tuple[str | None, str]] = {(None, n) for n in free_names(formula)}
    for e in subexpressions(formula):
        if isinstance(e, ast.Var) and e.prefix is not None:
            refs.add((e.prefix, e.name))
    return refs


def _unconstrained_outputs(node: ast.Node) -> list[Diagnostic]:
    mentioned: set[tuple[str | None, str]] = set()
    for clause in node.guarantees:
        mentioned |= _mentions(clause.formula)
    return [
        warning(out.loc,
                f"output {out.name} of {node.name} is not mentioned by any guarantee; "
                "the contract leaves it unconstrained",
                "W-unconstrained-output")
        for out in node.outputs
        if ("out", out.name) not in mentioned and (None, out.name) not in mentioned
    ]
