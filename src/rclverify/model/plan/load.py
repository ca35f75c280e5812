"""Load and validate the verification plan (``contracts/plan.yaml``).

The plan is YAML read with PyYAML's safe loader (through ``yaml.compose`` so
that every value keeps its line and column), validated against the JSON
schema ``plan.schema.json``, and then resolved against the type-checked
contracts (:func:`resolve`, :mod:`.resolve`): node names, guarantee indices, connection
variables and environment facts must all exist and type-check.  Every
mistake is a :class:`~rclverify.model.plan.errors.PlanError` located in the plan
file.  The format is documented in docs/plan.md.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.model.plan.document import EnvironmentEntry, PlanDocument, RequirementEntry, plan_document
from rclverify.model.plan.errors import PlanError, plan_error
from rclverify.model.plan.targets import requirement_target
from rclverify.model.plan.yamlguard import (KEY, Blocks, compose_guarded, read_yaml_text, schema_error_loc,
                                             schema_messages, to_data, yaml_error)

# The plan's values live in model/plan/model.py (below this loader and what it calls); re-exported here.
from rclverify.model.plan.model import Connection, DeadlineSpec, EvidenceEntry, Fact, Path_, Plan, Requirement, Support  # noqa: E402,F401
from rclverify.model.plan.paths import check_plan_paths
from rclverify.model.plan.state import read_state
from rclverify.model.plan.acknowledged import read_acknowledgements
from rclverify.lang.timing import UNITS, parse_duration
from rclverify.model.plan.standards.choice import read_standards
from rclverify.model.plan.instances import Instance, read_instances
from rclverify.model.plan.resolve import all_requirements, resolve

if TYPE_CHECKING:
    from rclverify.model.plan.formal import Source

__all__ = ["KEY", "Plan", "all_requirements", "load_plan", "read_plan_data", "read_plan_document", "resolve"]


def _schema() -> dict[str, Any]:
    from importlib import resources  # deferred: start-up (the schema is read only when a plan is validated, not on a kept pass)
    return json.loads(resources.files("rclverify.model.plan").joinpath("plan.schema.json").read_text(encoding="utf-8"))  # type: ignore[no-any-return]


def read_plan_data(root: Path, plan_rel: str) -> tuple[dict[str, Any], dict[Path_, ast.Loc]]:
    """Read ``root/plan_rel`` into plain data plus a location for every value path.

    Raises :class:`PlanError` on a missing file, bad YAML or a schema violation.
    """
    data, locs, _ = _read_plan_source(root, plan_rel)
    return data, locs


def read_plan_document(root: Path, plan_rel: str) -> tuple[PlanDocument, dict[Path_, ast.Loc]]:
    """Read ``root/plan_rel`` into its typed sections (:class:`~.document.PlanDocument`) plus a location
    for every value path.  Raises :class:`PlanError` on a missing file, bad YAML or a schema violation."""
    data, locs, _ = _read_plan_source(root, plan_rel)
    return plan_document(data, locs, plan_rel), locs


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
    from rclverify.core.cache.startup import read_kept  # deferred: start-up (loads rclverify.core.cache.store only when called)
    data, locs, blocks = read_kept(f"plan {plan_rel}", text, lambda t: _parse_plan(t, plan_rel))
    if not isinstance(data, dict):
        raise plan_error(plan_rel, 1, 1, "the verification plan must be a mapping with a 'contracts' list")
    _check_schema(data, locs, plan_rel, root)
    return data, locs, blocks


def _parse_plan(text: str, plan_rel: str) -> tuple[Any, dict[Path_, ast.Loc], Blocks]:
    """The plan's ``text`` as plain data, with a location for every value path and its block scalars
    (:func:`~.yamlguard.to_data`).  Raises :class:`PlanError` for YAML that is malformed or refused."""
    try:
        node = compose_guarded(text, plan_rel)
    except yaml_error() as exc:
        mark = getattr(exc, "problem_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise plan_error(plan_rel, line, col, f"invalid YAML: {getattr(exc, 'problem', exc)}", "E-yaml") from None
    locs: dict[Path_, ast.Loc] = {}
    blocks: Blocks = {}
    try:
        data = to_data(node, plan_rel, locs=locs, lines=text.splitlines(), blocks=blocks) if node is not None else None
    except yaml_error() as exc:  # e.g. a tag the safe loader does not construct
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise plan_error(plan_rel, line, col, f"invalid YAML: {getattr(exc, 'problem', exc)}", "E-yaml") from None
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
    import difflib  # deferred: start-up (a close spelling is only looked for in an error)
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
    doc = plan_document(data, locs, plan_rel)

    def loc(*path: Any) -> ast.Loc:
        return locs.get(tuple(path), ast.Loc(plan_rel, 1, 1))

    targets = check_plan_paths(root, plan_rel, doc, locs)
    contracts = _contract_files(root, plan_rel, doc, loc)
    reqs = [_requirement(i, r, loc, locs, blocks, plan_rel) for i, r in enumerate(doc.requirements)]
    conns = []
    for i, c in enumerate(doc.connections or ()):
        fn, fv = c.source.split(".", 1)
        tn, tv = c.to.split(".", 1)
        conns.append(Connection(fn, fv, tn, tv, loc("connections", i)))
    facts: dict[str, tuple[Fact, ...]] = {}
    instances: dict[str, tuple[int, int]] = {}
    for node, spec in (doc.environment or {}).items():
        facts[node] = _facts(node, spec, loc, blocks, plan_rel)
        if isinstance(spec, EnvironmentEntry) and spec.instances is not None:
            lo, hi = spec.instances
            instances[node] = (int(lo), int(hi))
    evidence: dict[str, tuple[EvidenceEntry, ...]] = {}
    replacements: dict[str, tuple[str, ast.Loc]] = {}
    for node, entry in (doc.nodes or {}).items():
        evidence[node] = tuple(EvidenceEntry(node, i, e["backend"], e, loc("nodes", node, "evidence", i))
                               for i, e in enumerate(entry.evidence))
        if entry.replacement is not None:
            replacements[node] = (entry.replacement, loc("nodes", node, "replacement"))
    rfrom = tuple((str(v), loc("requirements_from", k)) for k, v in doc.requirements_from.items())
    deadlines = _deadlines(doc, loc, plan_rel)
    states = read_state(doc, locs, blocks, plan_rel)
    if doc.fret_export:  # a FRET export's requirements (docs/requirements.md)
        from rclverify.model.plan.fret.requirements import plan_additions  # deferred: optional or conditional (inside a block)
        fret_reqs, fret_states = plan_additions(root, doc, contracts)
        reqs += fret_reqs
        states += fret_states
    return Plan(plan_rel, root, contracts, tuple(reqs), tuple(conns), facts, instances, evidence, replacements, locs,
                doc.name, dict(doc.ros or {}), rfrom, deadlines, states,
                read_acknowledgements(doc, locs, plan_rel), targets, read_standards(root, doc, locs, plan_rel),
                instances_of(doc.instances, locs, plan_rel), doc.design)


def _requirement(i: int, r: RequirementEntry, loc: Callable[..., ast.Loc], locs: Mapping[Path_, ast.Loc],
                 blocks: Blocks, plan_rel: str) -> Requirement:
    """The plan's ``requirements[i]`` (``r``) as a :class:`Requirement`: its formulas' sources located in
    the plan (block scalars read from their lines)."""
    sup = tuple(Support(s.node, s.guarantees, loc("requirements", i, "supported_by", j))
                for j, s in enumerate(r.supported_by))
    base: Path_ = ("requirements", i)
    assuming = (r.assuming,) if isinstance(r.assuming, str) else r.assuming or ()
    srcs = tuple(_source(base + ("assuming",) + ((j,) if isinstance(r.assuming, tuple) else ()), a, locs, blocks,
                         plan_rel) for j, a in enumerate(assuming))
    return Requirement(r.id, r.text.strip(), sup, loc(*base), _source(base + ("formal",), r.formal, locs, blocks,
                                                                         plan_rel),
                       tuple(x for x in srcs if x is not None),
                       ranking=_source(base + ("ranking",), r.ranking, locs, blocks, plan_rel),
                       invariant=_source(base + ("invariant",), r.invariant, locs, blocks, plan_rel),
                       strength=r.strength, target=requirement_target(r.target, loc(*base, "target")))


def _facts(node: str, spec: tuple[str, ...] | EnvironmentEntry, loc: Callable[..., ast.Loc], blocks: Blocks,
           plan_rel: str) -> tuple[Fact, ...]:
    """``environment.<node>``'s facts parsed (written as a list, or under ``facts:``); raises
    :class:`PlanError` with the parser's located diagnostics."""
    base: Path_ = ("environment", node) if isinstance(spec, tuple) else ("environment", node, "facts")
    texts = spec if isinstance(spec, tuple) else spec.facts
    out = []
    for i, text in enumerate(texts):
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
    return tuple(out)


def _contract_files(root: Path, plan_rel: str, doc: PlanDocument, loc: Callable[..., ast.Loc]) -> tuple[str, ...]:
    """The plan's contract files; one that does not exist is a located plan error (``E-io``)."""
    contracts = doc.contracts
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


def _deadlines(doc: PlanDocument, loc: Callable[..., ast.Loc], plan_rel: str) -> tuple[DeadlineSpec, ...]:
    """The requirements' ``deadline:`` entries (rule D3); a duration without
    a unit is a located plan error."""
    out = []
    for i, r in enumerate(doc.requirements):
        d = r.deadline
        if d is None:
            continue
        within = parse_duration(str(d.within))
        if within is None:
            l = loc("requirements", i, "deadline", "within")
            raise plan_error(plan_rel, l.line, l.col, f"deadline 'within: {d.within}' must be a positive number "
                             f"and a unit, e.g. '500 ms' (units: {', '.join(UNITS)})", "E-deadline")
        out.append(DeadlineSpec(r.id, d.path, within, loc("requirements", i, "deadline")))
    return tuple(out)


def _source(path: Path_, text: str | None, locs: Mapping[Path_, ast.Loc], blocks: Blocks,
            file: str) -> Source | None:
    """The :class:`~.formal.Source` of a formula ``text`` written at ``path``
    of the plan, or ``None`` when absent (``text`` is ``None``): a block
    scalar is read from its source lines, so every diagnostic maps onto the
    plan file."""
    if text is None:
        return None
    from rclverify.model.plan.formal import Source  # deferred: start-up (loaded only by a plan that writes a formula)
    block = blocks.get(path)
    if block is not None:
        return Source(block[1], block[0], 1, file)
    l = locs.get(path, ast.Loc(file, 1, 1))
    return Source(text, l.line, l.col, file)
