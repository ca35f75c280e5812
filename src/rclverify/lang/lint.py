"""Lint for RCL contracts: legal text that authors rarely mean.

``lint(spec)`` returns located warnings (severity ``"warning"``); it never
raises and never changes what a contract means.  The rules:

``W-implication-precedence``
    A *chain* whose meaning precedence decides: two or more ``->``/``<=>``
    in one unparenthesised run of connectives (``A -> B and C -> D`` reads
    as ``A -> ((B and C) -> D)``), or ``and`` and ``or`` mixed without
    parentheses (``A and B or C``).  One warning per chain, at its start,
    printing the parse with full parentheses.  The conventional forms
    ``(A and B) -> C`` written ``A and B -> C``, ``A or B -> C`` and
    ``A -> B and C`` are not warned about: every reader takes ``and``/``or``
    to bind tighter than ``->``.  The paper's own contracts show why chains
    deserve a warning: the Radiation Sensor guarantee of appendix A
    (shared/reference lines 1966-1983) reads, as printed, as one chain of
    implications, while its table and prose (lines 1290-1304, 1485-1492)
    mean separate conjuncts.
``W-unused-bound``
    A quantified variable that neither the quantifier's body nor a later
    binding's domain mentions (e.g. the ``x', y'`` of the Agent's third
    guarantee, listing at lines 1143-1171).
``W-unconstrained-output``
    A node output that no guarantee mentions: the contract says nothing
    about it, so no obligation will constrain it.

``W-lifecycle-unscoped``
    A guarantee of a lifecycle node (its contract names its
    ``lifecycle_msgs/TransitionEvent`` topic, :mod:`rclverify.lang.lifecycle`)
    with no ``while`` scope: it keeps the meaning it has always had (judged
    while the node is ``active``), and the warning says so, at the
    guarantee, so that the contract can state it (``while active``).

An input that no assumption or guarantee mentions is *not* reported: inputs
may be passed through or consumed only by the implementation.
"""
from __future__ import annotations

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, warning
from rclverify.lang.lifecycle import transition_topic
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.walk import free_names, subexpressions

_IMPLICATIONS = ("->", "<=>")
_JUNCTIONS = ("and", "or")


def lint(spec: ast.Spec) -> list[Diagnostic]:
    """All lint warnings of one parsed RCL file, sorted by location.

    ``spec``: a :class:`~rclverify.lang.ast.Spec` from the parser.
    Returns a list of :class:`~rclverify.lang.errors.Diagnostic` with
    severity ``"warning"`` and codes ``W-implication-precedence``,
    ``W-unused-bound``, ``W-unconstrained-output`` and ``W-lifecycle-unscoped``."""
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
        diags += _lifecycle_unscoped(node)
    return sorted(diags, key=lambda d: (d.loc.file, d.loc.line, d.loc.col, d.code))


# ---------------------------------------------------------------------------
# Traversal
# ---------------------------------------------------------------------------

# ---------------------------------------------------------------------------
# Rules
# ---------------------------------------------------------------------------

def _implication_precedence(formula: ast.Expr, where: str) -> list[Diagnostic]:
    diags = []
    inner: set[int] = set()  # ids of connective nodes that belong to a run started above them
    for e in subexpressions(formula):
        if not _is_connective(e) or id(e) in inner:
            continue
        run = _run(e)
        inner.update(id(x) for x in run[1:])
        ops = [x.op for x in run if isinstance(x, ast.Binary)]
        chain = sum(1 for o in ops if o in _IMPLICATIONS) >= 2
        mixed = any(isinstance(x, ast.Binary) and x.op in _JUNCTIONS and _mixes(x) for x in run)
        if chain or mixed:
            what = ("a chain of '->'/'<=>'" if chain else "'and' and 'or' mixed") + " without parentheses"
            diags.append(warning(
                e.loc,
                f"{where}: {what}; precedence decides its meaning, which is {full_parens(e)}; "
                "add parentheses to say which is meant",
                "W-implication-precedence"))
    return diags


def _is_connective(e: ast.Expr) -> bool:
    return isinstance(e, ast.Binary) and e.op in _IMPLICATIONS + _JUNCTIONS


def _run(e: ast.Expr) -> list[ast.Expr]:
    """``e`` and the connectives below it reached without crossing
    parentheses (an unparenthesised run of ``and``/``or``/``->``/``<=>``)."""
    out, todo = [], [e]
    while todo:
        x = todo.pop()
        out.append(x)
        if isinstance(x, ast.Binary):
            for c in (x.left, x.right):
                if _is_connective(c) and not getattr(c, "parenthesised", False):
                    todo.append(c)
    return out


def _mixes(x: ast.Binary) -> bool:
    """An ``and`` directly under an ``or`` (or the reverse), unparenthesised."""
    other = "or" if x.op == "and" else "and"
    return any(isinstance(c, ast.Binary) and c.op == other and not c.parenthesised for c in (x.left, x.right))


def full_parens(e: ast.Expr) -> str:
    """``e`` with every connective of its unparenthesised run wrapped in
    parentheses (operands outside the run printed canonically)."""
    if _is_connective(e) and isinstance(e, ast.Binary):
        return f"({_operand(e.left)} {e.op} {_operand(e.right)})"
    return expr_to_rcl(e)


def _operand(c: ast.Expr) -> str:
    if _is_connective(c) and not getattr(c, "parenthesised", False):
        return full_parens(c)
    text = expr_to_rcl(c)
    return text if not _is_connective(c) or text.startswith("(") else f"({text})"


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


def _lifecycle_unscoped(node: ast.Node) -> list[Diagnostic]:
    topic = transition_topic(node)
    if topic is None:
        return []
    return [warning(clause.loc,
                    f"guarantee {i} of {node.name}: {node.name} is a lifecycle node (it names its transition "
                    f"topic {topic.field}); an unscoped guarantee is judged only while the node is active; "
                    f"write 'while active' after it to say so, or the states it holds in",
                    "W-lifecycle-unscoped")
            for i, clause in enumerate(node.guarantees, 1) if clause.scope is None]
