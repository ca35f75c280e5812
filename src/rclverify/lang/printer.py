"""Pretty-printer from the RCL AST back to RCL text.

``to_rcl(spec)`` prints a whole file, ``expr_to_rcl(e)`` one formula or
term, ``type_to_rcl(t)`` one type (:mod:`rclverify.lang.type_printer`).  Parentheses are written only where the
fixed precedence of RCL requires them, so that

    parse_text(to_rcl(parse_text(src))) == parse_text(src)

for every file (AST equality ignores locations and the ``parenthesised``
flag).  Precedence, loosest first (the grammar in ``rcl.lark``, written from
the paper's EBNF table and listings, shared/reference lines 499-555 and
1131-1171):

====  ======================================  =============
level operators                               associativity
====  ======================================  =============
1     ``<=>``                                 left
2     ``->``                                  right
3     ``or``                                  left
4     ``and``                                 left
5     ``not``                                 prefix
6     comparisons ``== != < <= > >=``,        chained /
      membership ``in !in``                   none
7     ``+ -``                                 left
8     ``* /``                                 left
9     unary ``-``                             prefix
10    atoms: names, literals, applications,
      quantifiers, set/sequence/tuple literals
====  ======================================  =============

The level table is shared with :mod:`rclverify.lang.latex` through
:func:`level` and :func:`operand_levels`.
"""
from __future__ import annotations

import itertools

from typing import Union

from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.lang.type_printer import is_type as is_type, type_to_rcl as type_to_rcl

#: Precedence level of each binary operator (higher binds tighter).
BINARY_LEVEL: dict[str, int] = {
    "<=>": 1, "->": 2, "or": 3, "and": 4, "+": 7, "-": 7, "*": 8, "/": 8,
}
NOT_LEVEL = 5
COMPARE_LEVEL = 6
SUM_LEVEL = 7
MINUS_LEVEL = 9
ATOM_LEVEL = 10
#: Right-associative binary operators.
RIGHT_ASSOC = frozenset({"->"})


def level(e: ast.Expr) -> int:
    """The precedence level (1 = loosest, 10 = atom) of the operator at the
    root of ``e``; see the module table."""
    if isinstance(e, ast.Binary):
        return BINARY_LEVEL[e.op]
    if isinstance(e, ast.Unary):
        if e.op == "not":
            return NOT_LEVEL
        if e.op == "-":
            return MINUS_LEVEL
        if e.op == "abs" or e.op == "sqrt" or e.op == "sin" or e.op == "cos":
            return ATOM_LEVEL
        ast.unhandled(e.op)
    if isinstance(e, (ast.Compare, ast.Member)):
        return COMPARE_LEVEL
    return ATOM_LEVEL


def operand_levels(e: ast.Binary) -> tuple[int, int]:
    """Minimum levels the (left, right) operands of ``e`` must have to be
    printed without parentheses; an operand below its minimum is wrapped."""
    lv = BINARY_LEVEL[e.op]
    if e.op in RIGHT_ASSOC:
        return lv + 1, lv
    return lv, lv + 1


# ---------------------------------------------------------------------------
# Expressions
# ---------------------------------------------------------------------------

#: Associative connectives whose chains print flat (the parser reads a flat
#: chain as a balanced tree, chains.balanced).
FLAT_CHAINS = frozenset({"and", "or"})


def chain_operands(e: ast.Binary) -> list[ast.Expr]:
    """The operands of the maximal ``and``/``or`` chain rooted at ``e``, left
    to right: nested nodes of the same operator are opened unless the source
    parenthesised them (``Binary.parenthesised``).  Iterative, so a chain of
    any length or shape (balanced from the parser, left-nested when built by
    a program) prints flat without recursion."""
    out: list[ast.Expr] = []
    stack: list[ast.Expr] = [e.right, e.left]
    while stack:
        cur = stack.pop()
        if isinstance(cur, ast.Binary) and cur.op == e.op and not cur.parenthesised:
            stack += [cur.right, cur.left]
        else:
            out.append(cur)
    return out


#: Longest chain that is printed with inner parentheses when its tree is not
#: the balanced one the parser builds (a tree made by a program); a longer one
#: prints flat, which means the same by associativity.
EXACT_CHAIN_MAX = 64


#: Longest program-built chain whose printed parentheses are checked for minimality by reading the
#: text back (a few parses of a short text; longer chains keep every same-operator pair).
MINIMAL_CHAIN_MAX = 12


def _reads_back(text: str, e: ast.Expr) -> bool:
    """Whether ``text`` parses to ``e`` (AST equality ignores parentheses and locations)."""
    from rclverify.lang.parser import parse_formula  # deferred: start-up (loads lark, rclverify.core and more only when called)
    try:
        return parse_formula(text) == e
    except (RclError, RecursionError):
        return False


def _opens(x: ast.Expr, op: str) -> bool:
    return isinstance(x, ast.Binary) and x.op == op and not x.parenthesised


def is_balanced_chain(e: ast.Binary, n: int) -> bool:
    """Whether ``e`` is exactly the tree the parser builds for a flat chain
    of its ``n`` operands (chains.balanced: the first ceil(k/2) operands on
    the left at every level).  Iterative."""
    if n < 2:
        return False
    stack: list[tuple[ast.Expr, int]] = [(e.left, (n + 1) // 2), (e.right, n - (n + 1) // 2)]
    while stack:
        x, k = stack.pop()
        if k == 1:
            if _opens(x, e.op):
                return False
            continue
        if not _opens(x, e.op):
            return False
        assert isinstance(x, ast.Binary)
        half = (k + 1) // 2
        stack += [(x.left, half), (x.right, k - half)]
    return True


def clarifying_parens(e: ast.Binary, operand: ast.Expr) -> bool:
    """Whether ``operand`` of ``e`` is an ``and``/``or`` directly under
    ``->``/``<=>``: parentheses there are not required by precedence but
    state the reading explicitly (the case the lint rule
    ``W-implication-precedence`` warns about)."""
    return e.op in ("->", "<=>") and isinstance(operand, ast.Binary) and operand.op in ("and", "or")


def expr_to_rcl(e: ast.Expr, explicit: bool = False) -> str:
    """RCL text of a formula or term, parenthesised only where the
    precedence table requires.  With ``explicit=True`` an ``and``/``or``
    operand of ``->``/``<=>`` is parenthesised too (same AST, lint-clean
    text).  Quantifiers print as ``forall(x, y in REAL | body)``
    (``exists_unique`` for the unique existential).  Raises ``TypeError``
    for a value that is not an expression."""
    return _Printer(explicit).expr(e)


def binding_to_rcl(b: ast.Binding, explicit: bool = False) -> str:
    """``x', y' in REAL``: one binding of a quantifier."""
    return _Printer(explicit).binding(b)


class _Printer:
    def __init__(self, explicit: bool) -> None:
        self.explicit = explicit

    def wrap(self, e: ast.Expr, min_level: int, force: bool = False) -> str:
        s = self.expr(e)
        return f"({s})" if force or level(e) < min_level else s

    def items(self, items: tuple[ast.Expr, ...]) -> str:
        return ", ".join(self.expr(i) for i in items)

    def binding(self, b: ast.Binding) -> str:
        d = b.domain
        dom = type_to_rcl(d) if is_type(d) else self.wrap(d, SUM_LEVEL)  # type: ignore[arg-type]
        return ", ".join(b.names) + " in " + dom

    def expr(self, e: ast.Expr) -> str:
        return _expr(self, e)


def _expr(p: _Printer, e: ast.Expr) -> str:
    if isinstance(e, ast.Var):
        return e.qualified
    if isinstance(e, ast.BoolLit):
        return "TRUE" if e.value else "FALSE"
    if isinstance(e, ast.NumLit):
        return e.text + unit_to_rcl(e.unit)
    if isinstance(e, ast.Apply):
        return f"{e.func.qualified}({p.items(e.args)})"
    if isinstance(e, ast.First):
        return f"first({e.arg.qualified})"
    if isinstance(e, ast.Unary):
        if e.op == "not":
            return "not " + p.wrap(e.operand, NOT_LEVEL)
        if e.op == "-":
            inner = p.wrap(e.operand, MINUS_LEVEL)
            return "-" + inner if not inner.startswith("-") else "- " + inner
        if e.op == "abs" or e.op == "sqrt" or e.op == "sin" or e.op == "cos":
            return f"{e.op}({p.wrap(e.operand, 0)})"
        ast.unhandled(e.op)
    if isinstance(e, ast.Binary) and e.op in FLAT_CHAINS:
        ops = chain_operands(e)
        if len(ops) > EXACT_CHAIN_MAX or is_balanced_chain(e, len(ops)):
            # A parenthesised operand of the same operator keeps its
            # parentheses (level + 1 forces them), so re-parsing gives the
            # same tree.
            lv = BINARY_LEVEL[e.op]
            return f" {e.op} ".join(p.wrap(o, lv + 1) for o in ops)
        # Another shape (built by a program): same-operator operands in
        # parentheses, so that re-parsing rebuilds exactly this tree.
        lf = _opens(e.left, e.op) or (p.explicit and clarifying_parens(e, e.left))
        rf = _opens(e.right, e.op) or (p.explicit and clarifying_parens(e, e.right))
        lmin, rmin = operand_levels(e)
        text = f"{p.wrap(e.left, lmin, lf)} {e.op} {p.wrap(e.right, rmin, rf)}"
        if len(ops) <= MINIMAL_CHAIN_MAX and not p.explicit:
            # a pair the parser does not need goes (the printed text is minimal): the flat text of a
            # same-operator operand may balance back into exactly this tree ((a or (a or a)) or a)
            for drop_left in (True, False):
                if (lf if drop_left else rf):
                    bare = (f"{p.wrap(e.left, lmin, False)} {e.op} {p.wrap(e.right, rmin, rf)}" if drop_left else
                            f"{p.wrap(e.left, lmin, lf)} {e.op} {p.wrap(e.right, rmin, False)}")
                    if _reads_back(bare, e):
                        return bare
        return text
    if isinstance(e, ast.Binary):
        lmin, rmin = operand_levels(e)
        lf = p.explicit and clarifying_parens(e, e.left)
        rf = p.explicit and clarifying_parens(e, e.right)
        return f"{p.wrap(e.left, lmin, lf)} {e.op} {p.wrap(e.right, rmin, rf)}"
    if isinstance(e, ast.Compare):
        parts = [p.wrap(e.operands[0], SUM_LEVEL)]
        for op, operand in zip(e.ops, e.operands[1:]):
            parts += [op, p.wrap(operand, SUM_LEVEL)]
        return " ".join(parts)
    if isinstance(e, ast.Member):
        kw = "!in" if e.negated else "in"
        return f"{p.wrap(e.elem, SUM_LEVEL)} {kw} {p.wrap(e.collection, SUM_LEVEL)}"
    if isinstance(e, ast.SetLit):
        return "{" + p.items(e.items) + "}"
    if isinstance(e, ast.SeqLit):
        # The paper's angle brackets; items at sum level (a comparison inside
        # would read as the closing '>'), so anything looser is parenthesised.
        return "<" + ", ".join(p.wrap(i, SUM_LEVEL) for i in e.items) + ">"
    if isinstance(e, ast.SeqRange):
        return f"<{p.wrap(e.lo, SUM_LEVEL)} upto {p.wrap(e.hi, SUM_LEVEL)}>"
    if isinstance(e, ast.StrLit):
        return '"' + e.value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(e, ast.TupleQuant):
        d = e.domain
        dom = type_to_rcl(d) if is_type(d) else p.wrap(d, SUM_LEVEL)  # type: ignore[arg-type]
        return f"{e.kind}(({', '.join(e.names)}) in {dom} | {p.expr(e.body)})"
    if isinstance(e, ast.TupleLit):
        return "(" + p.items(e.items) + ")"
    if isinstance(e, ast.Quant):
        binds = ", ".join(p.binding(b) for b in e.bindings)
        return f"{e.kind}({binds} | {p.expr(e.body)})"
    raise TypeError(f"not an RCL expression: {e!r}")


# ---------------------------------------------------------------------------
# Declarations
# ---------------------------------------------------------------------------

def unit_to_rcl(u: ast.UnitAnn | None) -> str:
    """`` [m/s^2]`` (with the leading blank) for a unit of measure, ``""``
    for none (docs/rcl-language.md, "Units of measure")."""
    return f" [{u.text}]" if u is not None else ""


def io_var_to_rcl(v: ast.IOVar) -> str:
    """``d : REAL [m]``: one input or output declaration, its unit included."""
    return f"{v.name} : {type_to_rcl(v.type)}{unit_to_rcl(v.unit)}"


def _decl(d: Union[ast.TypeDecl, ast.ConstDecl], explicit: bool) -> str:
    if isinstance(d, ast.TypeDecl):
        return f"{d.name} : {type_to_rcl(d.type)} ;"
    typed = f" : {type_to_rcl(d.type)}{unit_to_rcl(d.unit)}" if d.type is not None else ""
    return f"{d.name}{typed} = {expr_to_rcl(d.value, explicit)} ;"


def context_to_rcl(c: ast.Context, explicit: bool = False) -> str:
    """``context { ... }`` with one declaration per line."""
    body = "".join(f"  {_decl(d, explicit)}\n" for d in c.decls)
    return "context {\n" + body + "}\n"


def _topic(t: ast.Topic) -> str:
    match = f" matches({t.match.qualified})" if t.match is not None else ""
    return f"{t.msg_type} {t.field}{match}"


def _link(lk: ast.Link) -> str:
    return f"{lk.ros_type} {lk.name} {lk.role}({', '.join(v.qualified for v in lk.parts)})"


def _timing(c: ast.Clause) -> str:
    """`` triggered by in.x within N unit while active`` (empty for an untimed, unscoped clause)."""
    s = f" triggered by {c.trigger.qualified}" if c.trigger is not None else ""
    if c.deadline is not None:
        s += f" within {c.deadline.amount}" + (f" {c.deadline.unit}" if c.deadline.unit else "")
    if c.scope is not None:
        s += " while " + " or ".join(c.scope.states)
    return s


def _io(vs: tuple[ast.IOVar, ...]) -> str:
    return ", ".join(io_var_to_rcl(v) for v in vs)


def node_to_rcl(n: ast.Node, explicit: bool = False) -> str:
    """``node Name { inputs(...) outputs(...) topics(...) assume(...)* guarantee(...)* }``.

    Assumptions are printed before guarantees (the AST keeps them apart),
    then ``initially``, ``progress``, ``periodic`` and the transition
    deadlines (``ready within ...``) in that order;
    ``topics(...)`` is omitted when the node has none."""
    lines = [f"node {n.name} {{", f"  inputs( {_io(n.inputs)} )", f"  outputs( {_io(n.outputs)} )"]
    if n.topics:
        sep = ",\n          "
        lines.append(f"  topics( {sep.join(_topic(t) for t in n.topics)} )")
    # one services(...) / actions(...) group per run of links of one kind, in the order written (the grammar
    # takes any number of groups), so that the printed text parses back to the same links
    sep = ",\n          "
    for kind, run in itertools.groupby(n.links, key=lambda lk: lk.kind):
        lines.append(f"  {kind}s( {sep.join(_link(lk) for lk in run)} )")
    lines += [f"  assume( {expr_to_rcl(c.formula, explicit)} )" for c in n.assumes]
    lines += [f"  guarantee( {expr_to_rcl(c.formula, explicit)} ){_timing(c)}" for c in n.guarantees]
    lines += [f"  initially( {expr_to_rcl(c.formula, explicit)} )" for c in n.initially]
    lines += [f"  progress( {progress_to_rcl(p)} )" for p in n.progress]
    lines += [f"  periodic( {p.output.qualified}, {p.amount}{' ' + p.unit if p.unit else ''} )" for p in n.periodic]
    lines += [f"  ready within {t.deadline.amount}{' ' + t.deadline.unit if t.deadline.unit else ''} of {t.transition}"
              for t in n.transitions]
    return "\n".join(lines) + "\n}\n"


def progress_to_rcl(p: ast.Progress) -> str:
    """``eventually`` or ``within K steps`` (the text inside ``progress( )``)."""
    if p.bound is None:
        return "eventually"
    return f"within {p.bound}" + (f" {p.unit}" if p.unit else "")


def to_rcl(spec: ast.Spec, explicit: bool = False) -> str:
    """RCL text of a whole file: its context clauses, then its nodes,
    separated by blank lines.  Comments and layout of the source are not
    kept; everything the AST holds is.  ``explicit``: see
    :func:`expr_to_rcl`."""
    parts = [context_to_rcl(c, explicit) for c in spec.contexts]
    parts += [node_to_rcl(n, explicit) for n in spec.nodes]
    return "\n".join(parts)
