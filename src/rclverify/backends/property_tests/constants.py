"""Every constant a node's contract or code compares with.

An off-by-one threshold (``<`` where the guarantee says ``<=``) shows only
at the threshold itself, and a random float lands on it almost never; so
the strategies draw the threshold and its neighbours beside arbitrary
values (:meth:`.strategies.InputSpace.real`: one ulp either side of a
float; ``integer``: one either side).  The thresholds are every number
either side compares with:

* the numeric literals of the node's assumptions and guarantees
  (:func:`.strategies.contract_constants`);
* the values of the context constants those clauses name
  (``ProtectiveDist = 0.5 ;``, evaluated, so ``Half = ProtectiveDist / 2``
  gives 0.25): :func:`named_constants`;
* the numbers the implementation's source compares with: the literals in a
  comparison (``if separation < 0.5``) and the module-level names it
  compares with (``PROTECTIVE_DIST``), read from the module's own values,
  and every module-level constant of numeric value named in capitals (the
  Python convention for a constant, PEP 8), whether or not a comparison
  names it directly: :func:`code_constants`.

Enumeration inputs are drawn from all their values already (each value is
its own boundary); booleans likewise.  Reading the code never runs it beyond
the import the backend makes anyway; a source that cannot be read adds
nothing (the contract's numbers are still drawn).
"""
from __future__ import annotations

import ast as pyast
import inspect
import math
import re
from fractions import Fraction
from functools import lru_cache
from typing import Any, Iterable

from rclverify.semantics.evaluator import Evaluator
from rclverify.lang import ast
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.walk import subexpressions

#: A module-level name written as a constant (PEP 8: capitals, digits and underscores).
_CONSTANT_NAME = re.compile(r"^_*[A-Z][A-Z0-9_]*$")
#: At most this many numbers from the code (a module of tables must not flood the draws).
MAX_CODE_CONSTANTS = 64


def _number(v: Any) -> Fraction | None:
    """``v`` as an exact number when it is a finite int or float (never a bool)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, Fraction)):
        return None
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return Fraction(v)


def constant_values(checked: Checked, node: CheckedNode) -> dict[str, Fraction]:
    """``{name: value}`` of the context constants ``node``'s assumptions and
    guarantees name, in source order (a constant whose value is not a
    number, or cannot be evaluated, is left out)."""
    out: dict[str, Fraction] = {}
    seen: set[str] = set()
    for clause in (*node.node.assumes, *node.node.guarantees):
        for e in subexpressions(clause.formula):
            if not isinstance(e, ast.Var) or e.prefix is not None or e.name in seen:
                continue
            seen.add(e.name)
            if e.name not in checked.env.constants or e.name in node.inputs or e.name in node.outputs:
                continue
            try:
                v = _number(Evaluator(checked, node, {}).eval(checked.env.constants[e.name][1], {}))
            except Exception:  # noqa: BLE001 - a constant the evaluator cannot take adds no boundary
                v = None
            if v is not None:
                out[e.name] = v
    return out


def named_constants(checked: Checked, node: CheckedNode) -> list[Fraction]:
    """The values of :func:`constant_values`, each once, in source order."""
    return list(dict.fromkeys(constant_values(checked, node).values()))


def _compared(tree: pyast.AST) -> tuple[list[Fraction], set[str]]:
    """The literal numbers in comparisons of ``tree`` and the names compared with."""
    numbers: list[Fraction] = []
    names: set[str] = set()
    for n in pyast.walk(tree):
        if not isinstance(n, pyast.Compare):
            continue
        for side in (n.left, *n.comparators):
            neg = isinstance(side, pyast.UnaryOp) and isinstance(side.op, pyast.USub)
            inner = side.operand if isinstance(side, pyast.UnaryOp) and neg else side
            x = _number(inner.value) if isinstance(inner, pyast.Constant) else None
            if x is not None:
                numbers.append(-x if neg else x)
            elif isinstance(inner, pyast.Name):
                names.add(inner.id)
            elif isinstance(inner, pyast.Attribute) and isinstance(inner.value, pyast.Name) \
                    and inner.value.id == "self":
                names.add(inner.attr)  # a class constant compared as self.LIMIT
    return numbers, names


@lru_cache(maxsize=32)
def _compared_in(source: str) -> tuple[tuple[Fraction, ...], frozenset[str]] | None:
    """:func:`_compared` of the Python text ``source`` (``None`` when it does
    not parse), once per text and process: a run imports its implementation
    afresh, but a module shared by many nodes' entries was parsed and walked
    again by each of their runs (65 ms a run for the 5000-node system's
    30 KB module); the result is a function of the text alone."""
    try:
        tree = pyast.parse(source)
    except (SyntaxError, ValueError):
        return None
    numbers, names = _compared(tree)
    return tuple(numbers), frozenset(names)


def code_constants(impl: Any) -> list[Fraction]:
    """The numbers the implementation ``impl`` (a function or a class)
    compares with, and its module's numeric constants named in capitals
    (module docstring), sorted, at most :data:`MAX_CODE_CONSTANTS`; ``[]``
    when its source cannot be read."""
    module = inspect.getmodule(impl)
    try:
        source = inspect.getsource(module) if module is not None else inspect.getsource(impl)
    except (OSError, TypeError):
        return []
    found_in = _compared_in(source)
    if found_in is None:
        return []
    numbers, names = found_in
    scope = {**(vars(module) if module is not None else {}), **(vars(impl) if inspect.isclass(impl) else {})}
    found: set[Fraction] = set(numbers)
    for name, v in scope.items():
        x = _number(v)
        if x is not None and (name in names or _CONSTANT_NAME.match(name)):
            found.add(x)
    return sorted(found, key=lambda x: (abs(x), x))[:MAX_CODE_CONSTANTS]


def boundary_constants(checked: Checked | None, node: CheckedNode, impl: Any = None,
                       literals: Iterable[Fraction] = ()) -> list[Fraction]:
    """Every threshold of ``node`` (module docstring): ``literals`` (the
    contract's numeric literals), the named constants its clauses use
    (``checked`` given) and the numbers ``impl``'s code compares with
    (``impl`` given); sorted, each once."""
    found = set(literals)
    if checked is not None:
        found.update(named_constants(checked, node))
    if impl is not None:
        found.update(code_constants(impl))
    return sorted(found)
