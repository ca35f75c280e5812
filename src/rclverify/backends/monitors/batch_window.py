"""What the batch path needs for windows: the window columns, their values as the engine maps them, and
why a question alone never decides a windowed guarantee.

A window variable (``NATURAL --> REAL`` mapped from an array field,
traces/mapping.py; :mod:`rclverify.targets.column_windows`) is held by the
batch path as a ``(rows, width)`` float64 column (:func:`window_column`): a
message whose field is a list of ``width`` finite floats is a row; any
other (another length, an integer, a boolean, a string, NaN, an infinity,
no list) is left to the engine, which maps it (or refuses it) itself.  Where
the engine's state keeps a message's value (the questions, the recent
outputs, the values in force), the batch path gives it the mapper's own
value (:func:`mappers`), so the engine reads what feeding the message
would have set.

**A question decides nothing** (:func:`answer_only`).  The engine
evaluates a question's guarantees on its inputs when it comes unless Z3
showed that only an answer decides them (needs_answer.py, which takes
quantifier-free scalar formulas only); it then gives ``satisfied`` at once
where they are true on the inputs alone.  The batch path judges a question
with its answer, so it takes a windowed guarantee only when no value of the
inputs makes it true without the outputs, shown on its syntax: a
comparison of an output (``out.y`` or ``out.y(t)``, a ``REAL``) with a
term that reads no output can be made false by the output; so can ``A and
B`` when ``A`` or ``B`` can, ``forall`` over a non-empty range when its
body can (at one offset), and ``exists`` over a range when its body can at
every offset through the output read at that offset alone (``out.y(k)``,
``k`` the offset it binds: one entry of the window per offset, so the
choices never meet).  Every input value then leaves an answer that makes
the guarantee false, so a sound judge never finds it true before the
answer: the engine's evaluation at the question gives no verdict, and the
question waits for its answer exactly as the batch path assumes.
"""
from __future__ import annotations

from itertools import chain
from operator import countOf
from typing import Any, Callable, Mapping

from rclverify.core.numeric import np

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.lang.types import CheckedNode
from rclverify.traces.mapping import TopicRule, value_mapper
from rclverify.targets.column_windows import is_window

_ORDERS = ("<", "<=", ">", ">=", "==", "!=")


def _floats(entries: list[Any]) -> bool:
    """Whether there are entries and every one is a ``float`` (its type read: an ``int``, a ``bool``, a
    string or a float subclass is not one).  The types are counted (``list.count`` compares each with
    ``float`` by identity first), not gathered into a set: about half the time."""
    return bool(entries) and list(map(type, entries)).count(float) == len(entries)


def window_column(vals: list[Any], width: int) -> tuple[np.ndarray, np.ndarray]:
    """(rows the columns hold, the ``(rows, width)`` float64 column; NaN where not held) of the values
    ``vals`` (a message's field each): a row holds a list of ``width`` finite floats (:func:`_floats`)."""
    n = len(vals)
    if not n:
        return np.zeros(0, dtype=bool), np.full((0, width), np.nan)
    if countOf(map(type, vals), list) == n and countOf(map(len, vals), width) == n:  # every row a list of width entries
        # the entries in one list, their types read in one pass and converted in one more, both at C speed
        # (a third of the time of one pass calling a converter per entry; np.fromiter on the list of floats
        # converts each as np.array does, without its search for the array's shape and type)
        entries = list(chain.from_iterable(vals))
        if _floats(entries):
            col = np.fromiter(entries, np.float64, n * width).reshape(n, width)
            return np.asarray(np.isfinite(col).all(axis=1)), col
    col = np.full((n, width), np.nan)
    good = np.fromiter((type(v) is list and len(v) == width for v in vals), bool, n)
    rows = [v for v, g in zip(vals, good.tolist()) if g]
    if rows and not _floats(list(chain.from_iterable(rows))):  # an integer, a boolean, a string...
        ok = np.fromiter((all(type(x) is float for x in v) for v in rows), bool, len(rows))
        idx = np.flatnonzero(good)
        good[idx[~ok]] = False
        rows = [v for v, o in zip(rows, ok.tolist()) if o]
    if rows:
        col[good] = np.fromiter(chain.from_iterable(rows), np.float64, len(rows) * width).reshape(len(rows), width)
    good &= np.isfinite(col).all(axis=1)
    return good, col


def mappers(node: CheckedNode, topics: Mapping[str, list[tuple[str, Any, bool]]], rules: Mapping[str, TopicRule]
            ) -> dict[str, Callable[[Mapping[str, object]], Any]]:
    """Each window variable's key -> its message's value as the engine's mapper maps it (``fields -> value``)."""
    out: dict[str, Callable[[Mapping[str, object]], Any]] = {}
    for topic, vs in topics.items():
        for key, typ, _ in vs:
            if is_window(typ):
                out[key] = _fresh(value_mapper(typ, rules[topic]))
    return out


def _fresh(mapper: Callable[[Mapping[str, object], Any], Any]) -> Callable[[Mapping[str, object]], Any]:
    """``mapper`` on a message alone: a window is the message's whole table, whatever came before."""
    return lambda fields: mapper(fields, None)


def answer_only(formula: ast.Expr, node: CheckedNode) -> bool:
    """Whether an output can make ``formula`` false whatever the inputs (module docstring): then a question's
    inputs alone never make it true."""
    return _falsified(formula, node, None)


def _output(e: Any, node: CheckedNode, at: str | None) -> bool:
    """Whether ``e`` is an output's ``REAL`` value (``out.y``) or window entry (``out.y(t)``; with ``at``,
    only ``out.y(at)``)."""
    if isinstance(e, ast.Apply) and len(e.args) == 1:
        arg = e.args[0]
        return _is_out(e.func, node) and is_window(node.io_type(e.func)) and \
            (at is None or (isinstance(arg, ast.Var) and arg.prefix is None and arg.name == at))
    return at is None and isinstance(e, ast.Var) and _is_out(e, node) and \
        node.io_type(e) == T.Scalar("REAL")


def _is_out(v: ast.Var, node: CheckedNode) -> bool:
    return v.prefix == "out" or (v.prefix is None and v.name in node.outputs and v.name not in node.inputs)


def _reads_out(e: Any, node: CheckedNode) -> bool:
    if isinstance(e, ast.Var):
        return _is_out(e, node)
    if isinstance(e, ast.Apply):
        return _reads_out(e.func, node) or any(_reads_out(a, node) for a in e.args)
    if isinstance(e, ast.Unary):
        return _reads_out(e.operand, node)
    if isinstance(e, ast.Binary):
        return _reads_out(e.left, node) or _reads_out(e.right, node)
    return not isinstance(e, (ast.NumLit, ast.BoolLit))  # anything else: assumed to read one


def _falsified(e: Any, node: CheckedNode, at: str | None) -> bool:
    if isinstance(e, ast.Compare) and len(e.ops) == 1 and e.ops[0] in _ORDERS:
        x, y = e.operands
        return (_output(x, node, at) and not _reads_out(y, node)) or (_output(y, node, at) and not _reads_out(x, node))
    if isinstance(e, ast.Binary) and e.op == "and":
        return _falsified(e.left, node, at) or _falsified(e.right, node, at)
    if isinstance(e, ast.Quant) and len(e.bindings) == 1 and len(e.bindings[0].names) == 1 and \
            isinstance(e.bindings[0].domain, ast.SeqRange):
        dom = e.bindings[0].domain
        if not (isinstance(dom.lo, ast.NumLit) and isinstance(dom.hi, ast.NumLit) and dom.lo.value <= dom.hi.value):
            return False
        if e.kind == "forall":
            return _falsified(e.body, node, at)
        if e.kind == "exists" and at is None:
            return _falsified(e.body, node, e.bindings[0].names[0])
    return False


__all__ = ["answer_only", "mappers", "window_column"]
