"""One RCL formula of one node compiled into a straight-line Python function
that evaluates it in exact arithmetic on concrete values, as the direct
evaluator does (:func:`rclverify.semantics.evaluate.evaluate`), for the
monitors' hot path ("compile each guarantee once into
straight-line Python").

The function (:attr:`Straight.fn`) takes the values (``"in.r"`` -> value,
:mod:`rclverify.semantics.values`) and returns the formula's truth, or raises
:class:`Missing` at the first I/O value the evaluation needs and that is
not there (``None`` or absent: not observed yet); any other exception means
"ask the evaluator" (a value of the wrong form, a division by zero, a
function value applied outside its table without a default...).  It is
generated from a jinja2 template (``templates/straightline.py.j2``): one
load per I/O value the formula reads, then the formula as one Python
expression in which

* every node is evaluated in the evaluator's order (the operands of a
  comparison and the arguments of an application left to right before it;
  ``and``, ``or`` and ``->`` short-circuit left to right), so a missing
  value is met exactly where :meth:`~rclverify.semantics.evaluator.Evaluator.io`
  would meet it, and a formula that holds whatever an absent output is
  (``in.command == inspect(i) -> ...`` for a ``move``) still holds;
* numbers are exact: literals are the evaluator's values (an ``int`` when
  whole, else a ``Fraction``), ``+ - * /`` call the exact meaning of their
  entry in the semantics table (:mod:`rclverify.semantics.operators`: a float
  is the rational it denotes), and comparisons and connectives are the
  Python text of their entries (comparisons exact between ``int``,
  ``float`` and ``Fraction``);
* names resolve as :meth:`~rclverify.semantics.evaluator.Evaluator.var`
  resolves them (an enumeration value, a named constant's expression, an
  argument-less constructor, else the node's input, else its output).

What is compiled: literals, names, applications of function values and
constructors, ``not`` and unary minus, ``and``/``or``/``->``/``<=>``,
arithmetic, comparisons (also chained) and membership in a set literal.
Quantifiers, membership in a type or a set-valued term, tuple, sequence and
string literals and ranges are not: :attr:`Straight.fallback` then says
which construct, and the caller evaluates that formula with the
evaluator, as before.  ``tests/semantics/test_straightline.py`` checks on random
formulas and values that the compiled function and the evaluator give the
same truth, the same missing value, and that the monitors' judgement is
unchanged.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any, Callable, Mapping, cast

from rclverify.core.cache.keys import fingerprint

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.visit import Visitor
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.values import Term
from rclverify.semantics.eval_values import Undecided
from rclverify.semantics.operators import OPERATORS, UNARY

if TYPE_CHECKING:
    import jinja2

#: Compiled formulas kept (per formula, node and environment); cleared when full.
CACHE_SIZE = 10_000


class Missing(Exception):
    """The formula needs the value of I/O variable ``key`` (``"out.status"``,
    the exception's one argument), which has none yet: the evaluator's
    ``no value for out.status``.  (No ``__init__`` of its own: raised at
    every input event of a node whose answer has not come yet.)"""

    @property
    def key(self) -> str:
        return str(self.args[0])


@dataclass(frozen=True)
class Straight:
    """A formula compiled for one node: ``fn(values) -> bool`` (``None`` when
    the formula is left to the evaluator, :attr:`fallback` saying why),
    ``source`` the generated Python text (``""`` when not compiled)."""

    fn: Callable[[Mapping[str, object]], bool] | None
    source: str
    fallback: str = ""


class _Unsupported(Exception):
    """A construct the straight-line code does not handle (its name in ``str``)."""


_CACHE: dict[tuple[int, int, int], tuple[Any, Any, Any, Straight]] = {}
_TEMPLATE: jinja2.Template | None = None


def compile_exact(formula: ast.Expr, checked: Checked, node: CheckedNode) -> Straight:
    """``formula`` of ``node`` as a straight-line function (module docstring),
    compiled once per (formula, node, environment) object and kept; never
    raises: a formula that cannot be compiled comes back with ``fn`` ``None``
    and the reason in ``fallback``."""
    env = checked.env
    key = (id(formula), id(node), id(env))
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is formula and hit[1] is node and hit[2] is env:
        return hit[3]
    try:
        out = _Gen(env, node).function(formula)
    except _Unsupported as exc:
        out = Straight(None, "", f"evaluated by the interpreter: {exc} is not compiled")
    except (RecursionError, MemoryError, SyntaxError) as exc:  # a formula too deep for Python's parser
        out = Straight(None, "", f"evaluated by the interpreter: the compiled code could not be built "
                                 f"({type(exc).__name__})")
    if len(_CACHE) >= CACHE_SIZE:
        _CACHE.clear()
    _CACHE[key] = (formula, node, env, out)
    return out


def _render(comment: str, loads: list[tuple[str, str]], body: str) -> str:
    """The template's text for a formula (``comment`` its RCL text, ``loads``
    its ``(local, key text)`` loads, ``body`` its expression): the same
    inputs always give the same text, so a process that keeps its start-up
    (:mod:`rclverify.core.cache.startup`) keeps it, keyed by these inputs
    (the template is rclverify's code, in the key's salt), and a run whose
    every formula is kept does not load jinja2."""
    from rclverify.core.cache.startup import active  # deferred: start-up (loads rclverify.core.cache.store only when called)
    kept = active()
    contents = ("rcl_formula", f"RCL: {comment}", fingerprint(loads), body)
    hit = kept.get("straightline", *contents) if kept is not None else None
    if isinstance(hit, str):
        return hit
    source = _template().render(name=contents[0], comment=contents[1], loads=loads, body=body)
    if kept is not None:
        kept.put("straightline", source, *contents)
    return source


def _template() -> jinja2.Template:
    import jinja2  # deferred: start-up (about 0.03 s; only a formula whose text is not kept is rendered)
    global _TEMPLATE
    if _TEMPLATE is None:
        _TEMPLATE = jinja2.Environment(
            loader=jinja2.PackageLoader("rclverify.semantics", "templates"), undefined=jinja2.StrictUndefined,
            autoescape=False, keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True,
        ).get_template("straightline.py.j2")
    return _TEMPLATE


def _missing(key: str) -> Any:
    raise Missing(key)


def _call(args: tuple[Any, ...], f: Any, what: str) -> Any:
    """``f(*args)`` as the evaluator applies a function value (the arguments
    evaluated first, then the function's name resolved)."""
    if not callable(f):
        raise Undecided(f"{what} is not a function value")
    return f(*args)


def _chain(ops: tuple[str, ...], vals: tuple[Any, ...]) -> bool:
    """A chained comparison ``a < b <= c``: every operand evaluated first, then
    the comparisons left to right (the evaluator's order), each the exact
    meaning of the semantics table."""
    return all(OPERATORS[op].exact(x, y) for op, x, y in zip(ops, vals, vals[1:]))


#: Nodes whose generated expression is already a ``bool``.
_BOOLEAN = (ast.Compare, ast.BoolLit, ast.Member)


class _Gen(Visitor[str]):
    """The code generator of one formula: the expression text, the I/O loads
    and the objects the code refers to by name (its namespace)."""

    def __init__(self, env: Any, node: CheckedNode) -> None:
        self.env, self.node = env, node
        self.loads: dict[str, str] = {}  # I/O key -> local name
        self.ns: dict[str, object] = {"_missing": _missing, "_call": _call, "_chain": _chain, "_Term": Term}
        #: operator symbol -> the name its exact meaning is bound to (the semantics table's entry)
        self.meanings: dict[str, str] = {}
        self.expanding: set[str] = set()  # named constants being expanded (a cycle is not compiled)

    def function(self, formula: ast.Expr) -> Straight:
        body = self.truth(formula)
        comment = " ".join(expr_to_rcl(formula).split())
        source = _render(comment, [(local, repr(key)) for key, local in self.loads.items()], body)
        code = compile(source, "<rcl formula>", "exec")
        ns = dict(self.ns)
        exec(code, ns)  # noqa: S102 - the source is generated above from the checked formula, no user text
        return Straight(cast(Callable[[Mapping[str, object]], bool], ns["rcl_formula"]), source)

    def const(self, value: Any) -> str:
        """A name in the namespace bound to ``value``."""
        name = f"_k{len(self.ns)}"
        self.ns[name] = value
        return name

    # -- booleans ---------------------------------------------------------------------
    def truth(self, e: Any) -> str:
        """``e`` as a ``bool`` expression (the evaluator's ``bool(...)``)."""
        code = self.expr(e)
        if isinstance(e, _BOOLEAN) or (isinstance(e, ast.Unary) and e.op == "not") or \
                (isinstance(e, ast.Binary) and e.op in ("and", "or", "->", "<=>")):
            return code
        return f"bool({code})"

    # -- values -----------------------------------------------------------------------
    def expr(self, e: Any) -> str:
        """``e`` as a Python expression: the method ``visit_<Class>`` of its
        class; a construct without one raises :class:`_Unsupported`."""
        return self.visit(e)

    def generic_visit(self, e: Any) -> str:
        raise _Unsupported(f"a {type(e).__name__}")

    def visit_BoolLit(self, e: ast.BoolLit) -> str:
        return "True" if e.value else "False"

    def visit_NumLit(self, e: ast.NumLit) -> str:
        v = e.value
        return repr(int(v)) if v.denominator == 1 else self.const(Fraction(v))

    def visit_Var(self, e: ast.Var) -> str:
        return self.var(e)

    def visit_Apply(self, e: ast.Apply) -> str:
        args = "".join(f"{self.expr(a)}, " for a in e.args)
        f = e.func
        if f.prefix is None and f.name in self.env.ctors:
            return f"_Term({f.name!r}, ({args}))"
        return f"_call(({args}), {self.var(f)}, {f.qualified!r})"

    def visit_Unary(self, e: ast.Unary) -> str:
        if e.op == "sqrt" or e.op == "sin" or e.op == "cos":  # the table's exact meaning itself (no Python operator)
            return f"{self.const(UNARY[e.op].exact)}({self.expr(e.operand)})"
        return cast(str, UNARY[e.op].python).format(x=self.expr(e.operand))

    def visit_Binary(self, e: ast.Binary) -> str:
        return self.binary(e)

    def visit_Compare(self, e: ast.Compare) -> str:
        vals = [self.expr(o) for o in e.operands]
        if len(e.ops) == 1:
            return cast(str, OPERATORS[e.ops[0]].python).format(l=vals[0], r=vals[1])
        return f"_chain({tuple(e.ops)!r}, ({', '.join(vals)},))"

    def visit_Member(self, e: ast.Member) -> str:
        if not isinstance(e.collection, ast.SetLit):
            raise _Unsupported("membership in a type or a set-valued term")
        elem = self.expr(e.elem)
        items = "".join(f"{self.expr(i)}, " for i in e.collection.items)
        coll = f"{{{items}}}" if items else "set()"
        return f"({elem} {'not in' if e.negated else 'in'} {coll})"

    def visit_Quant(self, e: ast.Quant) -> str:
        raise _Unsupported(f"a quantifier ({e.kind})")

    def visit_TupleQuant(self, e: ast.TupleQuant) -> str:
        raise _Unsupported(f"a quantifier ({e.kind})")

    def binary(self, e: ast.Binary) -> str:
        """A connective as the Python text of its entry in the semantics table
        (a chain of ``and``/``or`` flattened), arithmetic as a call of the
        entry's exact meaning."""
        op = e.op
        entry = OPERATORS[op]
        if op in ("and", "or"):
            parts = []
            stack: list[Any] = [e.right, e.left]
            while stack:  # the whole chain of one operator, left to right (no deep nesting)
                cur = stack.pop()
                if isinstance(cur, ast.Binary) and cur.op == op:
                    stack += [cur.right, cur.left]
                else:
                    parts.append(self.truth(cur))
            return "(" + f" {op} ".join(parts) + ")"
        if entry.kind == "connective":  # the left operand of -> is negated by the text itself
            left = self.expr(e.left) if op == "->" else self.truth(e.left)
            return cast(str, entry.python).format(l=left, r=self.truth(e.right))
        name = self.meanings.get(op)
        if name is None:
            name = self.meanings[op] = self.const(entry.exact)
        return f"{name}({self.expr(e.left)}, {self.expr(e.right)})"

    def var(self, v: ast.Var) -> str:
        """:meth:`Evaluator.var` for ``v`` (no variable is bound here)."""
        if v.prefix is None:
            name = v.name
            if name in self.env.enum_values:
                return repr(name)
            if name in self.env.constants:
                if name in self.expanding:
                    raise _Unsupported(f"the constant {name} defined through itself")
                self.expanding.add(name)
                try:
                    return f"({self.expr(self.env.constants[name][1])})"
                finally:
                    self.expanding.discard(name)
            if name in self.env.ctors:
                return self.const(Term(name, ()))
            key = ("in." + name) if name in self.node.inputs else ("out." + name)
        else:
            key = v.qualified
        local = self.loads.get(key)
        if local is None:
            local = self.loads[key] = f"_v{len(self.loads)}"
        return f"({local} if {local} is not None else _missing({key!r}))"


__all__ = ["CACHE_SIZE", "Missing", "Straight", "compile_exact"]
