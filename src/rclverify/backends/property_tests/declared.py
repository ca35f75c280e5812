"""A node's declarations checked on its implementation.

The property tests call the implementation on inputs drawn under the
node's assumption (docs/property-tests.md), and each call must return every
output, or the example fails.  So a run of a guarantee is also a test of
the node's declared progress on those inputs: every admissible input tried
got an answer.  Each property-test record carries one row per declaration
in ``details.declarations`` (the shape of the monitors' rows,
backends/monitors/declarations.py), read by the requirement roll-up
(calculus/requirements/rollup.py):

* ``progress( ... )`` and a period in steps (``periodic( out.y, N steps )``:
  every answer refreshes every output): ``true`` when the run passed (its
  valid examples, each answered with every output: testing evidence, not a
  proof); ``false`` when an example got no answer (the implementation
  raised, returned no mapping, or left an output out); otherwise
  ``inconclusive`` (the run stopped at another failure, or was not
  decided: not every input drawn was tried).
* ``initially( F )``: F judged on the implementation's initial outputs, when
  it gives them: a class's ``initial()`` on a fresh instance, or a
  function's ``initial`` attribute (a mapping of output name to value, or a
  callable returning one); the values follow the calling convention and
  must be values of the outputs' types.  ``true``/``false`` as F is; none
  given: ``pending`` (the monitors may judge it on a run).  The first
  answer is not the initial value (the node answers an input with it), so
  it is never taken for one.
* A period in time: not judged here (a function has no clock): no row.

A ``false`` row fails the record it is in only where the run itself did
not: an initial value outside F fails the record of guarantee 1 (once per
entry, not once per guarantee).
"""
from __future__ import annotations

import inspect
from typing import Any, Mapping

from rclverify.semantics.floatsem import judge
from rclverify.lang import ast
from rclverify.lang.liveness import STEP_WORDS
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.values import conforms, render
from rclverify.backends.shapes import DeclarationRow

#: the words of a counterexample's reason that say the implementation gave no answer (harness.check_step)
NO_ANSWER = ("the implementation raised", "the implementation returned", "the implementation's outputs do not match")
STATUS = {"true": "discharged", "false": "failed", "inconclusive": "inconclusive", "pending": "pending"}


def _src(loc: ast.Loc) -> str:
    return f"{loc.file}:{loc.line}:{loc.col}"


def _row(label: str, premise: str, index: int, source: str, text: str, verdict: str, reason: str) -> DeclarationRow:
    return {"declaration": label, "premise": premise, "index": index, "source": source, "text": text,
            "verdict": verdict, "status": STATUS[verdict], "reason": reason}


def has_declarations(node: CheckedNode) -> bool:
    """Whether ``node`` declares something the property tests judge."""
    n = node.node
    return bool(n.initially or n.progress or any(p.unit in STEP_WORDS for p in n.periodic))


def progress_verdict(status: str, counterexample: Mapping[str, str] | None, valid: int) -> tuple[str, str]:
    """The verdict on progress of one guarantee's run: its ``status``, its
    ``counterexample`` and its count of valid examples (module docstring)."""
    reason = str((counterexample or {}).get("reason", ""))
    if counterexample is not None and reason.startswith(NO_ANSWER):
        example = ", ".join(f"{k} = {v}" for k, v in counterexample.items() if k.startswith("in."))
        return "false", f"an admissible input got no answer ({example}): {reason}"
    if status == "discharged":
        return "true", f"{valid} admissible inputs tried, each answered with every output (tested, not proved)"
    return "inconclusive", f"the run ended {status}, not on a missing answer: not every input drawn was tried"


def initial_outputs(impl: Any) -> tuple[Mapping[str, object] | None, str]:
    """The implementation's initial outputs (module docstring) and, when
    there are none or they cannot be read, why (``(None, why)``)."""
    try:
        if inspect.isclass(impl):
            if not callable(getattr(impl, "initial", None)):
                return None, f"the class {impl.__name__} has no initial() method giving its initial outputs"
            got = getattr(impl(), "initial")()
        else:
            got = getattr(impl, "initial", None)
            if got is None:
                return None, f"{getattr(impl, '__name__', 'the implementation')} has no initial attribute giving its initial outputs"
            if callable(got):
                got = got()
    except Exception as exc:  # noqa: BLE001 - the user's code: its failure is the verdict's reason
        return None, f"reading the initial outputs raised {type(exc).__name__}: {exc}"
    if not isinstance(got, Mapping):
        return None, f"the initial outputs are {got!r}, not a mapping of output name to value"
    return got, ""


def initial_row(checked: Checked, node: CheckedNode, k: int, clause: ast.Clause,
                initial: Mapping[str, object] | None, why: str) -> DeclarationRow:
    """The row of ``initially`` number ``k`` on the initial outputs ``initial``."""
    text = f"initially( {expr_to_rcl(clause.formula)} )"
    src = _src(clause.loc)
    if initial is None:
        failed = why.startswith(("reading", "the initial outputs are"))
        return _row(f"initially {k}", "initial value", k, src, text, "false" if failed else "pending", why)
    values: dict[str, object] = {}
    for name, t in node.outputs.items():
        if name in initial:
            bad = conforms(initial[name], t)
            if bad:
                return _row(f"initially {k}", "initial value", k, src, text, "false",
                            f"the initial out.{name} is not a value of its type {t}: {bad}")
            values[f"out.{name}"] = initial[name]
    j = judge(clause.formula, checked, node, values)
    shown = ", ".join(f"{k2} = {render(v)}" for k2, v in sorted(values.items())) or "no output"
    if j.truth is True:
        return _row(f"initially {k}", "initial value", k, src, text, "true",
                    f"the implementation's initial outputs satisfy it: {shown}")
    if j.truth is False:
        return _row(f"initially {k}", "initial value", k, src, text, "false",
                    f"the implementation's initial outputs do not satisfy it: {shown}")
    return _row(f"initially {k}", "initial value", k, src, text, "inconclusive",
                f"undecided on the implementation's initial outputs ({shown}): {j.reason}")


def declaration_rows(checked: Checked, node: CheckedNode, impl: Any, status: str,
                     counterexample: Mapping[str, str] | None, valid: int) -> list[DeclarationRow]:
    """The rows of ``node``'s declarations from one guarantee's run (its
    ``status``, ``counterexample`` and valid example count) and the
    implementation ``impl`` (``None``: it could not be loaded; the initial
    values are then not judged)."""
    n = node.node
    rows = []
    initial, why = initial_outputs(impl) if impl is not None and n.initially else (None, "not loaded")
    for k, clause in enumerate(n.initially, 1):
        rows.append(initial_row(checked, node, k, clause, initial, why))
    verdict, reason = progress_verdict(status, counterexample, valid)
    for p in n.progress:
        rows.append(_row("progress", "progress", 0, _src(p.loc),
                         f"progress( {'eventually' if p.bound is None else f'within {p.bound} steps'} )",
                         verdict, reason))
    for per in n.periodic:
        if per.unit in STEP_WORDS:
            rows.append(_row(f"periodic out.{per.output.name}", "progress", 0, _src(per.loc),
                             f"periodic( out.{per.output.name}, {per.amount} {per.unit} )", verdict, reason))
    return rows
