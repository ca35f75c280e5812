"""The atoms of a space margin (docs/semantics.md, "Margins"): whether a
comparison measures a value of the run, and the words of the atom that decides
a margin.

* A comparison has a distance only when its terms read a value of the run:
  an input or output, or a variable bound to an element of a collection
  (:func:`measures_the_run`); any other atom is ``+inf`` or ``-inf``
  (:mod:`rclverify.semantics.robustness`).
* The atom that decides a margin is named by its RCL text (one link of a
  chained comparison: ``a <= b``) and the unit of its terms, the one the
  type checker's :class:`rclverify.lang.unitcheck.UnitChecker` gives
  (:func:`atom_words`; docs/rcl-language.md, "Units of measure").
"""
from __future__ import annotations

from typing import Any

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.lang.unitcheck import UnitChecker
from rclverify.lang.units import best_name, canonical_text


def measured_terms(terms: Any, b: Any, idx: frozenset[str], io: frozenset[str]) -> bool:
    """Whether ``terms`` read a value of the run: an input or output (``io``:
    the node's I/O names), or a variable bound (``b``: the bound names) to an
    element of a collection (not one ranging over a type, ``idx``)."""
    for t in terms:
        for v in term_vars(t):
            if v.prefix is not None or (v.name in b and v.name not in idx) or (v.name not in b and v.name in io):
                return True
    return False


def term_vars(e: Any) -> list[ast.Var]:
    """The variables of term ``e``, an applied function's name among them
    (``in.x(k)`` reads the run's ``in.x``; a constructor's name is no I/O value)."""
    hit = _VARS.get(id(e))
    if hit is not None and hit[0] is e:
        return hit[1]
    out: list[ast.Var] = []
    stack = [e]
    while stack:
        x = stack.pop()
        if isinstance(x, ast.Var):
            out.append(x)
        elif isinstance(x, ast.Apply):
            stack.append(x.func)
            stack.extend(x.args)
        elif isinstance(x, tuple):
            stack.extend(x)
        elif hasattr(x, "__dataclass_fields__") and not isinstance(x, ast.Loc):
            stack.extend(getattr(x, f) for f in x.__dataclass_fields__ if f not in ("loc", "name_locs"))
    if len(_VARS) >= 10_000:
        _VARS.clear()
    _VARS[id(e)] = (e, out)
    return out


_VARS: dict[int, tuple[Any, list[ast.Var]]] = {}


def _unit(checked: Checked, node: CheckedNode, e: Any, i: int, bound: frozenset[str]) -> str:
    """The unit text of the compared terms of atom ``e`` (operands ``i`` and ``i + 1``
    of a comparison; the element and items of a membership), ``""`` when none is known."""
    units = UnitChecker(lambda *_: None)
    units.constants = dict(checked.env.units)
    if isinstance(e, ast.Compare):
        terms = [e.operands[i], e.operands[i + 1]]
    else:
        terms = [e.elem, e.collection]
    for t in terms:
        q = units.term(t, node, bound)
        if q.kind == "unit" and q.unit is not None:
            u = q.unit
            return u.text or best_name(u) or canonical_text(u)
    return ""


def atom_words(checked: Checked, node: CheckedNode, atom: ast.Compare | ast.Member, i: int,
               bound: frozenset[str] = frozenset()) -> tuple[str, str]:
    """``(text, unit)`` of a deciding atom: link ``i`` of comparison ``atom``
    (its RCL text, ``a <= b``) or membership ``atom``, under the bound names
    ``bound``, and the unit of its terms (``""``: none declared); computed once per atom."""
    key = (id(atom), i, bound, id(node), id(checked))
    hit = _ATOMS.get(key)
    if hit is None or hit[0] is not atom:
        text = expr_to_rcl(atom) if not isinstance(atom, ast.Compare) or len(atom.ops) == 1 else \
            expr_to_rcl(ast.Compare((atom.ops[i],), (atom.operands[i], atom.operands[i + 1])))
        if len(_ATOMS) >= 4096:
            _ATOMS.clear()
        hit = _ATOMS[key] = (atom, text, _unit(checked, node, atom, i, bound))
    return hit[1], hit[2]


#: (atom id, link, bound names, node id, contract id) -> (the atom, its text, its unit): computed once per atom
_ATOMS: dict[tuple[Any, ...], tuple[Any, str, str]] = {}


def measures_the_run(terms: Any, io: frozenset[str]) -> bool:
    """Whether the terms of a comparison outside every quantifier read a value
    of the run (an input or output; ``io``: the node's I/O names): else the
    comparison has no distance (``+inf`` or ``-inf``; module docstring)."""
    return measured_terms(terms, frozenset(), frozenset(), io)


__all__ = ["atom_words", "measured_terms", "measures_the_run", "term_vars"]
