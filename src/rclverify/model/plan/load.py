"""Load and validate the verification plan (``contracts/plan.yaml``).

The plan is YAML read with PyYAML's safe loader (through ``yaml.compose`` so
that every value keeps its line and column), validated against the JSON
schema ``plan.schema.json``, and then resolved against the type-checked
contracts (:func:`resolve`): node names, guarantee indices, connection
variables and environment facts must all exist and type-check.  Every
mistake is a :class:`~rclverify.model.plan.errors.PlanError` located in the plan
file.  The format is documented in docs/plan.md.
"""
from __future__ import annotations

import difflib

import json
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

import yaml

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import BOOL, Checked
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.formal import Source
from rclverify.model.plan.targets import check_targets, requirement_target
from rclverify.model.plan.yamlguard import (KEY, Blocks, compose_guarded, read_yaml_text, schema_error_loc,
                                             schema_messages, to_data)

# The plan's values live in model/plan/model.py (below this loader and what it calls); re-exported here.
from rclverify.model.plan.model import Connection, DeadlineSpec, EvidenceEntry, Fact, Path_, Plan, Requirement, Support  # noqa: E402,F401
from rclverify.model.plan.paths import check_plan_paths
from rclverify.model.plan.state import read_state, state_types, check_states
from rclverify.model.plan.acknowledged import check_acknowledgements, read_acknowledgements
from rclverify.lang.timing import UNITS, parse_duration
from rclverify.model.plan.formal import parse_formal
from rclverify.model.plan.ranking import parse_hints
from rclverify.model.plan.temporal import Temporal, parse_temporal, shape
from rclverify.model.plan.expected import check_expected
from rclverify.model.plan.declarations import BACKEND_NAMES
from rclverify.model.plan.entries import unknown_key_messages
from rclverify.model.plan.standards.choice import read_standards
from rclverify.model.plan.instances import Instance, read_instances

__all__ = ["KEY", "Plan", "load_plan", "read_plan_data", "resolve"]


def _schema() -> dict[str, Any]:
    return json.loads(resources.files("rclverify.model.plan").joinpath("plan.schema.json").read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def read_plan_data(root: Path, plan_rel: str) -> tuple[dict[str, Any], dict[Path_, ast.Loc]]:
    """Read ``root/plan_rel`` into plain data plus a location for every value path.

    Raises :class:`PlanError` on a missing file, bad YAML or a schema violation.
    """
    data, locs, _ = _read_plan_source(root, plan_rel)
    return data, locs


def _read_plan_source(root: Path, plan_rel: str) -> tuple[dict[str, Any], dict[Path_, ast.Loc], Blocks]:
    p = root / plan_rel
    try:
        text = read_yaml_text(p, plan_rel)
    except PlanError as exc:
        d = exc.diagnostics[0]
        if d.code != "E-io":
            raise
        raise plan_error(plan_rel, 1, 1, d.message.replace("cannot read file", "cannot read the verification plan"),
                         "E-io") from None
    try:
        node = compose_guarded(text, plan_rel)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise plan_error(plan_rel, line, col, f"invalid YAML: {getattr(exc, 'problem', exc)}", "E-yaml") from None
    locs: dict[Path_, ast.Loc] = {}
    blocks: Blocks = {}
    try:
        data = to_data(node, plan_rel, locs=locs, lines=text.splitlines(), blocks=blocks) if node is not None else None
    except yaml.YAMLError as exc:  # e.g. a tag the safe loader does not construct
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise plan_error(plan_rel, line, col, f"invalid YAML: {getattr(exc, 'problem', exc)}", "E-yaml") from None
    if not isinstance(data, dict):
        raise plan_error(plan_rel, 1, 1, "the verification plan must be a mapping with a 'contracts' list")
    _check_schema(data, locs, plan_rel, root)
    return data, locs, blocks


def _node_names(root: Path | None, data: Mapping[str, Any]) -> list[str]:
    """The node names of the plan's contract files that parse (none when they cannot be read): only
    asked for a message, so a file that does not parse is reported later, where it is checked."""
    from rclverify.lang.parser import parse_file  # deferred: start-up (only for an error's message)
    names: list[str] = []
    files = data.get("contracts")
    if root is None or not isinstance(files, list):
        return names
    for c in files:
        try:
            names += [n.name for n in parse_file(root / str(c)).nodes]
        except (RclError, OSError):
            continue
    return names


def _not_a_node(e: Any, root: Path | None, data: Mapping[str, Any]) -> str | None:
    """The message of a schema error that a key under ``nodes:`` is not a node's entry, when that key
    names no node of the contracts (an unknown key, e.g. a node's key indented one level too high)."""
    path = tuple(e.absolute_path)
    if e.validator != "type" or len(path) != 2 or path[0] != "nodes":
        return None
    names = _node_names(root, data)
    key = str(path[1])
    if key in names:
        return None
    close = difflib.get_close_matches(key, names, n=1, cutoff=0.6)
    entry = difflib.get_close_matches(key, ["evidence", "replacement"], n=1, cutoff=0.6)
    hint = (f" (did you mean the node {close[0]!r}?)" if close else
            f" (did you mean a node's {entry[0]!r}? indent it under the node's name)" if entry else "")
    return (f"nodes.{key}: unknown key {key!r}: no node of the contracts is named so{hint}; under 'nodes' each key "
            f"is a node's name with its entry (evidence, replacement); the nodes are: {', '.join(names) or 'none read'}")


def _check_schema(data: dict[str, Any], locs: Mapping[Path_, ast.Loc], plan_rel: str,
                  root: Path | None = None) -> None:
    """Validate the plan's ``data`` against ``plan.schema.json``; raises
    :class:`PlanError` with a located diagnostic per violation (``locs``).
    A pass is kept by a process that keeps its start-up
    (:mod:`rclverify.core.cache.startup`, keyed by the data, the schema and
    jsonschema's files): the same data passes again without loading
    jsonschema; a failure is never kept."""
    from rclverify.core.cache.keys import fingerprint  # deferred: start-up (loads rclverify.core.cache only when called)
    from rclverify.core.cache.startup import active  # deferred: start-up (loads rclverify.core.cache.store only when called)
    kept = active()
    try:
        key = fingerprint(data) if kept is not None else None
    except TypeError:  # a value neither marshal nor JSON holds (a YAML timestamp): validated, not kept
        key = None
    if key is not None and kept is not None and kept.get("plan-schema", key) is True:
        return
    import jsonschema  # here, not at module level: a doit run that reuses the cached workspace never validates; deferred: start-up (loads jsonschema only when called)
    errors = sorted(jsonschema.Draft202012Validator(_schema()).iter_errors(data), key=lambda e: list(map(str, e.absolute_path)))
    if not errors and key is not None and kept is not None:
        kept.put("plan-schema", True, key)
    if errors:
        diags: list[Diagnostic] = []
        for e, message in schema_messages(errors, lambda e: ".".join(map(str, e.absolute_path)) or "plan"):
            message = _not_a_node(e, root, data) or message
            loc = schema_error_loc(e, locs, plan_rel)
            if message.startswith("nodes.") and " unknown key " in message:
                loc = locs.get(("nodes", e.absolute_path[1], KEY), loc)  # at the key itself
            diags.extend(plan_error(loc.file, loc.line, loc.col, message).diagnostics)
        raise PlanError(diags)


def load_plan(root: Path, plan_rel: str = "contracts/plan.yaml") -> Plan:
    """Read and schema-check the plan (contract-independent part).

    Raises :class:`PlanError`.  Call :func:`resolve` once the contracts are
    checked to validate the references into them.
    """
    data, locs, blocks = _read_plan_source(root, plan_rel)

    def loc(*path: Any) -> ast.Loc:
        return locs.get(tuple(path), ast.Loc(plan_rel, 1, 1))

    targets = check_plan_paths(root, plan_rel, data, locs)
    contracts = _contract_files(root, plan_rel, data, loc)
    reqs = []
    for i, r in enumerate(data.get("requirements", [])):
        sup = tuple(Support(s["node"], tuple(s["guarantees"]), loc("requirements", i, "supported_by", j))
                    for j, s in enumerate(r.get("supported_by", [])))
        formal = _source(("requirements", i, "formal"), r, "formal", locs, blocks, plan_rel)
        assuming = r.get("assuming", [])
        assuming = [assuming] if isinstance(assuming, str) else assuming
        srcs = tuple(_source(("requirements", i, "assuming") + ((j,) if isinstance(r["assuming"], list) else ()),
                             {"v": a}, "v", locs, blocks, plan_rel) for j, a in enumerate(assuming))
        reqs.append(Requirement(str(r["id"]), str(r["text"]).strip(), sup, loc("requirements", i), formal,
                                tuple(x for x in srcs if x is not None),
                                ranking=_source(("requirements", i, "ranking"), r, "ranking", locs, blocks, plan_rel),
                                invariant=_source(("requirements", i, "invariant"), r, "invariant", locs, blocks,
                                                  plan_rel),
                                strength=r.get("strength"),
                                target=requirement_target(r.get("target"), loc("requirements", i, "target"))))
    conns = []
    for i, c in enumerate(data.get("connections", []) or []):
        fn, fv = c["from"].split(".", 1)
        tn, tv = c["to"].split(".", 1)
        conns.append(Connection(fn, fv, tn, tv, loc("connections", i)))
    facts: dict[str, tuple[Fact, ...]] = {}
    instances: dict[str, tuple[int, int]] = {}
    for node, spec in (data.get("environment") or {}).items():
        if isinstance(spec, list):
            spec = {"facts": spec}
            base: Path_ = ("environment", node)
        else:
            base = ("environment", node, "facts")
        out = []
        for i, text in enumerate(spec.get("facts", [])):
            l = loc(*base, i)
            block = blocks.get(tuple(base) + (i,))
            from rclverify.lang.parser import parse_formula  # deferred: start-up (loads lark; only a plan with environment facts parses a formula here)
            try:
                if block is not None:
                    expr = parse_formula(block[1], plan_rel, block[0], 1)
                    l = ast.Loc(plan_rel, block[0], len(block[1]) - len(block[1].lstrip()) + 1)
                else:
                    expr = parse_formula(text, plan_rel, l.line, l.col)
            except RclError as exc:
                raise PlanError(exc.diagnostics) from None
            out.append(Fact(node, text, expr, l))
        facts[node] = tuple(out)
        if "instances" in spec:
            lo, hi = spec["instances"]
            instances[node] = (int(lo), int(hi))
    evidence: dict[str, tuple[EvidenceEntry, ...]] = {}
    replacements: dict[str, tuple[str, ast.Loc]] = {}
    for node, spec in (data.get("nodes") or {}).items():
        evidence[node] = tuple(EvidenceEntry(node, i, e["backend"], e, loc("nodes", node, "evidence", i))
                               for i, e in enumerate(spec.get("evidence", [])))
        if "replacement" in spec:
            replacements[node] = (spec["replacement"], loc("nodes", node, "replacement"))
    rfrom = tuple((str(v), loc("requirements_from", k)) for k, v in (data.get("requirements_from") or {}).items())
    deadlines = _deadlines(data, loc, plan_rel)
    states = read_state(data, locs, blocks, plan_rel)
    if (data.get("requirements_from") or {}).get("fret"):  # a FRET export's requirements (docs/requirements.md)
        from rclverify.model.plan.fret.requirements import plan_additions  # deferred: optional or conditional (inside a block)
        fret_reqs, fret_states = plan_additions(root, data, contracts)
        reqs += fret_reqs
        states += fret_states
    return Plan(plan_rel, root, contracts, tuple(reqs), tuple(conns), facts, instances, evidence, replacements, locs,
                str(data.get("name", "")), dict(data.get("ros") or {}), rfrom, deadlines, states,
                read_acknowledgements(data, locs, plan_rel), targets, read_standards(root, data, locs, plan_rel),
                instances_of(data.get("instances"), locs, plan_rel), str(data.get("design") or ""))


def _contract_files(root: Path, plan_rel: str, data: Mapping[str, Any], loc: Any) -> tuple[str, ...]:
    """The plan's contract files; one that does not exist is a located plan error (``E-io``)."""
    contracts = tuple(data["contracts"])
    for i, c in enumerate(contracts):
        if not (root / c).is_file():
            l = loc("contracts", i)
            raise plan_error(plan_rel, l.line, l.col, f"contract file {c!r} does not exist", "E-io")
    return contracts


def instances_of(data: Any, locs: Mapping[Path_, ast.Loc], plan_rel: str) -> dict[str, tuple[Instance, ...]]:
    """The plan's ``instances`` (:func:`.instances.read_instances`); raises :class:`PlanError` with
    every problem located (``E-instances``)."""
    got, wrong = read_instances(data, locs, plan_rel)
    if wrong:
        raise PlanError([d for l, msg in wrong for d in plan_error(l.file, l.line, l.col, msg, "E-instances").diagnostics])
    return got


def _deadlines(data: Mapping[str, Any], loc: Any, plan_rel: str) -> tuple[DeadlineSpec, ...]:
    """The requirements' ``deadline:`` entries (rule D3); a duration without
    a unit is a located plan error."""
    out = []
    for i, r in enumerate(data.get("requirements", [])):
        d = r.get("deadline")
        if d is None:
            continue
        within = parse_duration(d["within"])
        if within is None:
            l = loc("requirements", i, "deadline", "within")
            raise plan_error(plan_rel, l.line, l.col, f"deadline 'within: {d['within']}' must be a positive number "
                             f"and a unit, e.g. '500 ms' (units: {', '.join(UNITS)})", "E-deadline")
        out.append(DeadlineSpec(str(r["id"]), tuple(d["path"]), within, loc("requirements", i, "deadline")))
    return tuple(out)


def _source(path: Path_, holder: Mapping[str, Any], key: str, locs: Mapping[Path_, ast.Loc], blocks: Blocks,
            file: str) -> Source | None:
    """The :class:`~.formal.Source` of a formula written at ``path`` of the
    plan (``holder[key]``), or ``None`` when absent: a block scalar is read
    from its source lines, so every diagnostic maps onto the plan file."""
    if key not in holder:
        return None
    block = blocks.get(path)
    if block is not None:
        return Source(block[1], block[0], 1, file)
    l = locs.get(path, ast.Loc(file, 1, 1))
    return Source(str(holder[key]), l.line, l.col, file)


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
