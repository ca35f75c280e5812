"""The plan resolved against the type-checked contracts (:func:`resolve`):
node names, guarantee indices, connection variables, environment facts,
requirements (the plan's and its Doorstop trees', :func:`all_requirements`)
and evidence entries must all exist and type-check; every mistake is a
located :class:`~rclverify.model.plan.errors.PlanError`.  The format is
documented in docs/plan.md.
"""
from __future__ import annotations

from typing import Any, Sequence

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import BOOL, Checked
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.yamlguard import KEY
from rclverify.model.plan.targets import check_targets
from rclverify.model.plan.model import Plan, Requirement
from rclverify.model.plan.state import state_types, check_states
from rclverify.model.plan.acknowledged import check_acknowledgements
from rclverify.model.plan.expected import check_expected
from rclverify.model.plan.declarations import BACKEND_NAMES
from rclverify.model.plan.entries import unknown_key_messages


def all_requirements(plan: Plan) -> tuple[Requirement, ...]:
    """The plan's requirements, then those of its ``requirements_from``
    Doorstop trees (:mod:`.doorstop`).  Raises :class:`PlanError` when a tree
    cannot be read."""
    out = list(plan.requirements)
    if plan.requirements_from:
        from rclverify.model.plan.doorstop import read_requirements  # deferred: optional or conditional (inside a block)
        for folder, l in plan.requirements_from:
            if l == plan.locs.get(("requirements_from", "fret")):
                continue  # a FRET export's requirements are the plan's own (.fret.requirements.plan_additions)
            out.extend(read_requirements(plan.root, folder, l))
    return tuple(out)


def check_formal(reqs: tuple[Requirement, ...], checked: Checked, states: tuple[Any, ...] = ()) -> list[Diagnostic]:
    """Located errors of the requirements' ids (each once) and formal
    statements (:func:`.temporal.parse_temporal`: unknown node or variable, an
    input written as an output, a type error, a temporal operator's bound;
    ``states`` the plan's declared state variables, :mod:`.state`)."""
    stypes = state_types(tuple(states), checked)
    diags: list[Diagnostic] = []
    seen: dict[str, Requirement] = {}
    for r in reqs:
        if r.id in seen:
            o = seen[r.id]
            diags.extend(plan_error(r.loc.file, r.loc.line, r.loc.col, f"requirement id {r.id!r} is used twice "
                                    f"(first at {o.loc.file}:{o.loc.line}:{o.loc.col})").diagnostics)
        seen.setdefault(r.id, r)
        if r.formal:
            from rclverify.model.plan.ranking import parse_hints  # deferred: start-up (loaded only by a plan that has formal statements)
            from rclverify.model.plan.temporal import Temporal, parse_temporal, shape  # deferred: start-up (loaded only by a plan that has formal statements)
            try:
                t = parse_temporal(r.formal, checked, f"{r.id} formal", stypes)
                if isinstance(t, Temporal):
                    shape(t, r.formal.loc)  # a nesting that is not decided: a located E-temporal error
                parse_hints(r.ranking, r.invariant, t, checked, r.id, stypes)  # ranking:/invariant: (.ranking)
            except RclError as exc:
                diags.extend(exc.diagnostics)
        elif r.ranking or r.invariant:
            src = r.ranking or r.invariant
            assert src is not None
            diags.append(error(src.loc, f"{r.id}: ranking:/invariant: need a liveness statement in formal: "
                                        "(eventually F, or F until G)", "E-temporal"))
        for src, what in [(a, f"{r.id} assuming") for a in r.assuming]:
            from rclverify.model.plan.formal import parse_formal  # deferred: start-up (loaded only by a plan that has formal statements)
            try:
                parse_formal(src, checked, what)
            except RclError as exc:
                diags.extend(exc.diagnostics)
    return diags


def resolve(plan: Plan, checked: Checked) -> None:
    """Check the plan's references into the contracts.

    Every node named must exist, guarantee indices must be in range,
    connection endpoints must be an output and an input of equal type, and
    environment facts must be well-typed formulas of their node, and every
    evidence entry must name a registered backend (:mod:`.entries`) and only
    its keys.  Raises :class:`PlanError` listing every problem.  A backend's
    own check of its entries' files is
    :func:`rclverify.backends.entry_checks.check_entries`, which the caller
    runs after this (``Workspace.checked``).
    """
    refs = _References(checked)
    diags = refs.diags
    try:
        reqs = all_requirements(plan)
    except PlanError as exc:
        diags.extend(exc.diagnostics)
        reqs = plan.requirements
    refs.support(reqs)
    diags.extend(check_formal(reqs, checked, plan.states))
    diags.extend(check_states(plan.states, checked))
    for d in plan.deadlines:
        for n in d.path:
            if not refs.node_ok(n, d.loc):
                break
    refs.connections(plan)
    refs.instances(plan)
    refs.facts(plan)
    refs.entries(plan)
    diags.extend(check_targets(plan, checked))  # statistical targets, environment tags, run origins (docs/statistics.md)
    # The backends' own check-time validation (experiment data and criteria,
    # review records, trace mappings) is run by the layer above both
    # (rclverify.app.pipeline.Workspace.checked calls backends.entry_checks), so
    # the plan imports no backend code.
    # expected verdicts: a malformed entry is an error here, not a report row
    diags.extend(check_expected(plan, checked))
    diags.extend(check_acknowledgements(plan.acknowledged, plan.locs, checked))  # one finding each (docs/plan.md)
    if diags:
        raise PlanError(diags)


class _References:
    """The plan's references into the contracts checked one kind at a time
    (:func:`resolve`), each problem a located diagnostic in ``diags``."""

    def __init__(self, checked: Checked) -> None:
        self.checked, self.nodes = checked, checked.nodes
        self.diags: list[Diagnostic] = []

    def bad(self, l: ast.Loc, msg: str) -> None:
        self.diags.extend(plan_error(l.file, l.line, l.col, msg).diagnostics)

    def node_ok(self, name: str, l: ast.Loc) -> bool:
        if name in self.nodes:
            return True
        self.bad(l, f"no node named {name!r} in the contracts; nodes are: {', '.join(self.nodes)}")
        return False

    def support(self, reqs: Sequence[Requirement]) -> None:
        """A requirement's ``support``: its nodes exist, its guarantee indices are in range."""
        for r in reqs:
            for s in r.support:
                if self.node_ok(s.node, s.loc):
                    n = len(self.nodes[s.node].node.guarantees)
                    for g in s.guarantees:
                        if not 1 <= g <= n:
                            self.bad(s.loc, f"{r.id}: node {s.node} has {n} guarantee(s); there is no guarantee {g}")

    def connections(self, plan: Plan) -> None:
        """A connection joins an output and an input of equal type."""
        nodes, bad = self.nodes, self.bad
        for c in plan.connections:
            if self.node_ok(c.from_node, c.loc) and self.node_ok(c.to_node, c.loc):
                ot = nodes[c.from_node].outputs.get(c.from_var)
                it = nodes[c.to_node].inputs.get(c.to_var)
                if ot is None:
                    bad(c.loc, f"{c.from_node} has no output {c.from_var!r}")
                if it is None:
                    bad(c.loc, f"{c.to_node} has no input {c.to_var!r}")
                if ot is not None and it is not None and ot != it:
                    bad(c.loc, f"connection joins {c.from_node}.{c.from_var} : {ot} to {c.to_node}.{c.to_var} : {it}")

    def instances(self, plan: Plan) -> None:
        """An instanced contract exists, and no instance takes the name of another contract's node."""
        for contract, insts in plan.node_instances.items():
            l = plan.locs.get(("instances", contract, KEY), insts[0].loc if insts else ast.Loc(plan.file, 1, 1))
            if not self.node_ok(contract, l):
                continue
            from rclverify.model.instances import instance_node  # deferred: only a plan with instances
            from rclverify.model.names import BadName  # deferred: as above
            for i in insts:
                if i.name != contract and i.name in self.nodes:
                    self.bad(i.loc, f"the instance of {contract} in {i.namespace} is named {i.name}, "
                                    f"as a contract's node is: rename one")
                try:
                    instance_node(self.nodes[contract], i)
                except BadName as exc:
                    self.bad(i.loc, f"the instance of {contract} in {i.namespace}: {exc}")

    def facts(self, plan: Plan) -> None:
        """An environment fact is a well-typed formula of its node."""
        from rclverify.lang.typecheck import infer  # deferred: start-up (loads lark, rclverify.core and more only when called)
        for node, facts in plan.facts.items():
            for f in facts:
                if not self.node_ok(node, f.loc):
                    break
                try:
                    t = infer(f.expr, self.nodes[node], self.checked.env)
                except RclError as exc:
                    self.diags.extend(exc.diagnostics)
                    continue
                if t != BOOL:
                    self.bad(f.loc, f"an environment fact must be a formula, found {t}")

    def entries(self, plan: Plan) -> None:
        """An evidence entry names a registered backend and only its keys."""
        for node, entries in plan.evidence.items():
            if entries:
                self.node_ok(node, entries[0].loc)
            for e in entries:
                if e.backend not in BACKEND_NAMES:
                    bl = plan.locs.get(("nodes", node, "evidence", e.index, "backend"), e.loc)
                    self.bad(bl, f"unknown backend {e.backend!r}; known backends: {', '.join(BACKEND_NAMES)}")
                for key, msg in unknown_key_messages(e.backend, e.config):
                    path = ("nodes", node, "evidence", e.index, key)
                    self.bad(plan.locs.get(path + (KEY,), plan.locs.get(path, e.loc)), msg)
