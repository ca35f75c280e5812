"""Which guarantees only an answer can decide (a speed fact, never a verdict).

The monitor evaluates a question's guarantees when the question comes
(docs/monitors.md, "An answer comes after its question"), on its inputs and
the state outputs, before any answer: a guarantee whose inputs alone decide
it (``in.on -> ...`` with ``in.on`` false) is ``satisfied`` or failed there.
For most guarantees the evaluation only meets a missing output, and that
costs about a fifth of the engine's time on a classifier.

:func:`answer_decides` asks Z3 once per node whether **no** value of the
inputs decides a guarantee without the outputs: neither ``forall out. G``
nor ``forall out. not G`` holds for any value of the inputs.  Then an
evaluation on the inputs alone can only meet a missing output (a value
computed without reading an output would be the same for every output, so
one of the two would hold), and the monitor skips it.  The argument needs
the recorded values to lie in Z3's domains, so it is made only where they
do:

* every formula of the node is quantifier-free, over inputs of type REAL,
  BOOL or an enumeration (a recorded INTEGER could be 2.5), scalar
  outputs, numbers, enumeration
  values and ``+ - *``, comparisons and the connectives: no division, no
  function, no set or sequence (nothing that can raise while evaluating);
* the node has no state outputs (all its outputs are missing at the
  question) and no ``triggered by`` guarantee;
* a REAL input's recorded value is a finite number: the value mappers
  refuse NaN and the infinities (``traces/mapping.py``; that event is
  ``inconclusive``), which Z3's reals do not have.

Anything else, and any ``unknown`` from Z3, answers ``False``: evaluate as
before.  Skipping never changes a verdict, its guarantee, its reason or when
it is decided; ``tests/backends/test_monitor_needs_answer.py`` checks the verdicts
with and without on random traces.
"""
from __future__ import annotations

import io
import pickle
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.types import BOOL, INTEGER, NATURAL, REAL, Checked, CheckedNode, EnumT

#: Z3's budget for each of the two queries of a guarantee (ms).
QUERY_MS = 500
_SCALARS = (REAL, INTEGER, NATURAL, BOOL)
_OPS = ("<=>", "->", "or", "and", "+", "-", "*")
#: (id of the checked system, node, ids of the formulas) -> (the system, the answer)
_CACHE: dict[tuple[Any, ...], tuple[Checked, bool]] = {}


def _plain(e: ast.Expr) -> bool:
    """Quantifier-free, division-free, function-free scalar formula?"""
    if isinstance(e, (ast.BoolLit, ast.NumLit, ast.Var)):
        return True
    if isinstance(e, ast.Unary):  # sqrt/sin/cos: functions
        return e.op in ("not", "-", "abs") and _plain(e.operand)
    if isinstance(e, ast.Binary):
        return e.op in _OPS and _plain(e.left) and _plain(e.right)
    if isinstance(e, ast.Compare):
        return all(_plain(x) for x in e.operands)
    return False


def _scalar(t: Any) -> bool:
    return t in _SCALARS or isinstance(t, EnumT)


def answer_decides(checked: Checked, node: CheckedNode, formulas: Iterable[ast.Expr]) -> bool:
    """``True`` when Z3 shows that no value of ``node``'s inputs decides any
    of ``formulas`` (its guarantees) without its outputs; ``False`` when a
    value may, when a formula is outside the fragment above, or when Z3
    cannot say within :data:`QUERY_MS` per query.  Raises nothing."""
    formulas = list(formulas)
    if not formulas or not all(_plain(f) for f in formulas):
        return False
    if not all(t in (REAL, BOOL) or isinstance(t, EnumT) for t in node.inputs.values()):
        return False
    if not all(_scalar(t) for t in node.outputs.values()):
        return False
    key = (id(checked), node.name, tuple(map(id, formulas)))
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is checked:
        return hit[1]
    answer = _kept(checked, node, formulas)
    if len(_CACHE) >= 64:
        _CACHE.clear()
    _CACHE[key] = (checked, answer)
    return answer


def _kept(checked: Checked, node: CheckedNode, formulas: list[ast.Expr]) -> bool:
    """:func:`_decides`, kept by a process that keeps its start-up
    (:mod:`rclverify.core.cache.startup`) under the pickled environment, node
    and formulas (all the query reads; Z3's files in the key's salt)."""
    from rclverify.core.cache.startup import active  # deferred: start-up (loads rclverify.core.cache.store only when called)
    kept = active()
    if kept is None:
        return _decides(checked, node, formulas)
    try:
        content = _content((checked.env, node, tuple(formulas)))
    except Exception:  # noqa: BLE001 - a value pickle refuses (or a cycle): asked, not kept
        return _decides(checked, node, formulas)
    hit = kept.get("needs-answer", content)
    if isinstance(hit, bool):
        return hit
    answer = _decides(checked, node, formulas)
    kept.put("needs-answer", answer, content)
    return answer


def _content(value: Any) -> bytes:
    """``value`` pickled without the memo (pickle's fast mode): every object
    written in full wherever it occurs, so the bytes are the same whether
    the contracts were parsed in this process or read back from the cache
    (which share their strings differently).  Raises ``ValueError`` for a
    cyclic value, ``pickle.PicklingError`` for one pickle cannot hold."""
    buf = io.BytesIO()
    p = pickle.Pickler(buf, protocol=4)
    p.fast = True
    p.dump(value)
    return buf.getvalue()


def _decides(checked: Checked, node: CheckedNode, formulas: list[ast.Expr]) -> bool:
    import z3  # deferred: start-up (Z3 only for a node whose formulas are in the fragment)
    from rclverify.semantics.connectives import conj  # deferred: start-up (loads z3 only when called)
    from rclverify.semantics.encode import Encoder  # deferred: start-up (loads z3 and the encoder only when called)
    from rclverify.semantics.query import budgeted_solver  # deferred: start-up (loads z3 only when called)
    try:
        enc = Encoder(checked.env)
        outs = [enc.io_symbol(node, "out", v) for v in sorted(node.outputs)]
        encoded = [enc.formula(f, node) for f in formulas]
        typed = conj(*enc.axioms()) if enc.axioms() else z3.BoolVal(True)
        for g in encoded:
            for goal in (g, z3.Not(g)):
                s = budgeted_solver(QUERY_MS)  # resource steps decide, not the clock
                s.add(z3.ForAll(outs, z3.Implies(typed, goal)) if outs else goal)
                if s.check() != z3.unsat:  # a value of the inputs decides it (or Z3 cannot say)
                    return False
    except Exception:  # noqa: BLE001 - a speed fact: anything unexpected keeps the evaluation
        return False
    return True


__all__ = ["QUERY_MS", "answer_decides"]
