"""Declared state variables of a node: the plan's ``state:`` section.

A contract of the paper relates one input element to one output element
(lines 462-495); a node whose behaviour depends on what it did before (the
case study's Agent keeps the set of waypoints it has inspected) has memory
the contracts do not name.  The plan declares it (docs/plan.md, "state")::

    state:
      Agent:
        inspected:
          type: InspectedType
          init: "forall(i in NATURAL | state.inspected(i) == FALSE)"
          next: "forall(i in NATURAL | next.inspected(i) == TRUE <=>
                   (state.inspected(i) == TRUE or out.command == inspect(i)))"

``type`` is a context type name or a base type (``NATURAL``, ``INTEGER``,
``REAL``, ``BOOL``, ``STRING``); ``init`` is an RCL formula over
``state.v`` (the value at the first step); ``next`` an RCL formula over
``state.v`` (its value at this step), ``next.v`` (at the next step) and the
node's ``in.x``/``out.y`` at this step.  Requirements name the variable
``Node.state.v`` (:mod:`.formal`), only under a temporal operator.

A state variable is a *history variable*: it observes the node's inputs and
outputs and constrains nothing else, so declaring it never removes a run of
the composed contracts.  That holds when ``next`` gives every state exactly
one next value (a definition); the transition system
(:mod:`rclverify.calculus.requirements.transition`) checks that ``init`` and ``next``
are satisfiable, and reports a declaration that blocks every run.

Formulas are read like requirements (:mod:`.formal`): each ``state.v`` /
``next.v`` is replaced by a placeholder of the same length, so every
diagnostic lands on the plan's line and column.
"""
from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import BOOL, INTEGER, NATURAL, REAL, STRING, Checked, CheckedNode, Type
from rclverify.model.plan.document import PlanDocument
import json

if TYPE_CHECKING:
    from rclverify.model.plan.formal import Source

#: ``state.v`` / ``next.v`` in a declaration's formulas.
STATE_REF = re.compile(r"(?<![A-Za-z0-9_.'])(state|next)\.([A-Za-z_][A-Za-z0-9_]*)")
BASE_TYPES: dict[str, Type] = {"NATURAL": NATURAL, "INTEGER": INTEGER, "REAL": REAL, "BOOL": BOOL,
                               "STRING": STRING}


@dataclass(frozen=True)
class StateVar:
    """One declared state variable ``node.state.name`` of type ``type_name``;
    ``init``/``next`` the sources of its formulas; ``loc`` the declaration."""

    node: str
    name: str
    type_name: str
    init: Source
    next: Source
    loc: ast.Loc
    type_loc: ast.Loc


@dataclass(frozen=True)
class StateFormula:
    """A parsed declaration formula: ``expr`` over the node's I/O and the
    pseudo inputs ``state.v``/``next.v`` of ``scope``."""

    expr: ast.Expr
    scope: CheckedNode


def read_state(doc: PlanDocument, locs: Mapping[tuple[Any, ...], ast.Loc], blocks: Mapping[tuple[Any, ...], tuple[int, str]],
               file: str) -> tuple[StateVar, ...]:
    """The plan's ``state:`` section (``doc``: the plan's typed sections) as values, in
    order of writing.  ``locs``/``blocks`` are the loader's locations."""
    out = []
    for node, vars_ in (doc.state or {}).items():
        for name, spec in vars_.items():
            base = ("state", node, name)
            loc = locs.get(base, ast.Loc(file, 1, 1))

            def src(key: str, text: str) -> Source:
                from rclverify.model.plan.formal import Source  # deferred: start-up (loaded only by a plan that declares a state)
                block = blocks.get(base + (key,))
                if block is not None:
                    return Source(block[1], block[0], 1, file)
                l = locs.get(base + (key,), loc)
                return Source(text, l.line, l.col, file)
            out.append(StateVar(node, name, spec.type, src("init", spec.init), src("next", spec.next), loc,
                                locs.get(base + ("type",), loc)))
    return tuple(out)


def state_type(sv: StateVar, checked: Checked) -> Type:
    """The resolved type of ``sv``; raises :class:`RclError` (``E-type``,
    at the ``type:`` entry) for a name that is neither a context type nor a
    base type."""
    t = checked.env.types.get(sv.type_name) or BASE_TYPES.get(sv.type_name)
    if t is None:
        raise RclError([error(sv.type_loc, f"state {sv.node}.{sv.name}: unknown type {sv.type_name!r}; context "
                                           f"types are: {', '.join(checked.env.types) or 'none'}", "E-type")])
    return t


def state_types(states: tuple[StateVar, ...], checked: Checked) -> dict[tuple[str, str], Type]:
    """``{(node, name): type}`` of the declarations that resolve (errors are
    :func:`check_states`'s business)."""
    out: dict[tuple[str, str], Type] = {}
    for sv in states:
        try:
            out[(sv.node, sv.name)] = state_type(sv, checked)
        except RclError:
            pass
    return out


def parse_state_formula(sv: StateVar, which: str, checked: Checked, states: tuple[StateVar, ...]) -> StateFormula:
    """Parse and type-check ``sv``'s ``init`` or ``next`` (``which``).

    ``init`` may mention only ``state.v`` of the node's variables; ``next``
    also ``next.v`` and the node's ``in.x``/``out.y``.  Raises
    :class:`RclError` with located diagnostics (``E-name``, ``E-type``).
    """
    from rclverify.lang.parser import parse_formula  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.lang.typecheck import infer  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.model.plan.formal import _loc_at, _rename  # deferred: start-up (loaded only by a plan that declares a state)
    src = sv.init if which == "init" else sv.next
    what = f"state {sv.node}.{sv.name} {which}"
    cn = checked.nodes.get(sv.node)
    if cn is None:
        raise RclError([error(sv.loc, f"state: no node named {sv.node!r} in the system; nodes are: "
                                      f"{', '.join(checked.nodes) or 'none'}", "E-name")])
    mine = {s.name: state_type(s, checked) for s in states if s.node == sv.node}
    diags: list[Diagnostic] = []
    names: dict[str, str] = {}
    pieces, last = [], 0
    for k, m in enumerate(STATE_REF.finditer(src.text)):
        kind, var = m.group(1), m.group(2)
        if var not in mine:
            diags.append(error(_loc_at(src, m.start()), f"{what}: {sv.node} declares no state variable {var!r}; "
                                                        f"it declares: {', '.join(mine)}", "E-name"))
        elif kind == "next" and which == "init":
            diags.append(error(_loc_at(src, m.start()), f"{what}: init gives the first value; next.{var} "
                                                        "belongs in next:", "E-name"))
        ph = f"__s{k}_"
        ph = ph + "_" * (m.end() - m.start() - len(ph)) if len(ph) <= m.end() - m.start() else ph
        names[ph] = f"{kind}.{var}"
        pieces.append(src.text[last:m.start()] + ph)
        last = m.end()
    pieces.append(src.text[last:])
    if which == "init":
        for m in re.finditer(r"(?<![A-Za-z0-9_.'])(in|out)\.[A-Za-z_]", src.text):
            diags.append(error(_loc_at(src, m.start()), f"{what}: init gives the first value of the state; it "
                                                        "cannot read the node's inputs or outputs", "E-name"))
    if diags:
        raise RclError(diags)
    expr = _rename(parse_formula("".join(pieces), src.file, src.line, src.col), names)
    ins: dict[str, Type] = dict(cn.inputs) if which == "next" else {}
    ins.update({f"state.{v}": t for v, t in mine.items()})
    if which == "next":
        ins.update({f"next.{v}": t for v, t in mine.items()})
    scope = CheckedNode(dataclasses.replace(cn.node, name=sv.node), ins, dict(cn.outputs) if which == "next" else {})
    t = infer(expr, scope, checked.env)
    if t != BOOL:
        raise RclError([error(src.loc, f"{what}: must be a formula, found a term of type {t}", "E-type")])
    return StateFormula(expr, scope)


def check_states(states: tuple[StateVar, ...], checked: Checked) -> list[Diagnostic]:
    """Located errors of the declarations: unknown node or type, a name
    that is already an input or output of the node, formulas that do not
    parse or type-check (:func:`parse_state_formula`)."""
    diags: list[Diagnostic] = []
    for sv in states:
        try:
            state_type(sv, checked)  # Node.state.v and Node.in.v are different names: no clash
            for which in (("init", "next") if sv.node in checked.nodes else ("init",)):
                try:
                    parse_state_formula(sv, which, checked, states)
                except RclError as exc:
                    diags.extend(exc.diagnostics)
        except RclError as exc:
            diags.extend(exc.diagnostics)
    return diags


def state_key(node: str) -> str:
    """The key of ``node``'s state declarations among the hashes a
    requirement record is compared with (``rclverify.stages.provenance.state_hashes``)."""
    return f"state:{node}"


def state_sha256(states: tuple[StateVar, ...], node: str) -> str:
    """sha256 of ``node``'s state declarations (type, init, next; none: the
    empty list), so that a ``state:`` edit makes the records that read them stale."""
    import hashlib  # deferred: start-up (loads hashlib only when called)
    text = json.dumps([[s.name, s.type_name, s.init.text, s.next.text] for s in states if s.node == node])
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
