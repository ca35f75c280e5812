"""The ``instances`` stage: the plan's instances as the system runs them, and each requirement
about instanced contracts decided for every namespace (docs/plan.md, "Instances in the report").

A plan with ``instances:`` runs one contract as several nodes (:mod:`rclverify.model.instances`).
The contracts stay types: their obligations and evidence are the type's, one obligation for every
instance.  This stage writes what the fleet adds, as one sealed record
``artifacts/instances/index.json`` that the report shows (:func:`instances_row`):

* ``instances``: per instance its node (``Relay_r1``), contract, namespace, ROS node (``/r1/relay``),
  where the plan gives it, each topic, service and action name of the contract with the name it
  resolves to in the namespace (as rcl resolves it, :func:`rclverify.model.names.resolve`), and
  each input with the output feeding it (``source``) in the fleet's system model
  (:func:`rclverify.model.instances.fleet_system`: ``via`` ``"instance"``, ``"topic"``,
  ``"name"`` or ``"plan"``) or ``null`` when it is the environment's;
* ``requirements``: every requirement whose formal statement names an instanced contract is
  read as quantified over the namespaces those contracts run in ("for every robot r"), and
  decided once per namespace ``r`` in which each of them has an instance: the statement's
  ``C.in.x``/``C.out.y`` of each instanced contract ``C`` become ``C_r``'s, the other contracts
  stay as written, and Z3 decides it from the guarantees of its cone in the fleet's system model
  (:func:`rclverify.calculus.requirements.check.check_requirement`).  A namespace in which one of
  them has no instance is listed with the verdict ``inconclusive`` and the contracts missing
  there.  The type-level check (the ``requirements`` stage) is unchanged: a statement proved
  over the types can be refuted for a robot whose instance is fed from elsewhere or from the
  environment (a fleet-wide topic named relative, so that every robot reads its own);
* ``inputs``: the sha256 of the plan and its contract files (:func:`rclverify.records.records.hash_inputs`);
  :func:`read_instances` calls a record made from other files ``stale``.

The ``requirements`` task runs the stage after its own (``app/task_actions.py``); a plan without
``instances:`` has no record and the report's ``instances`` is ``null``.  The record is a pure
function of its inputs: every verdict is decided again each time the stage runs.
"""
from __future__ import annotations

import dataclasses
import re
from typing import TYPE_CHECKING, Any, Mapping, Sequence

from rclverify.records.records import hash_inputs
from rclverify.records.sealed import read_sealed, write_sealed

if TYPE_CHECKING:
    from rclverify.model.plan.instances import Instance
    from rclverify.model.plan.model import Plan, Requirement
    from rclverify.records.instance_rows import InstancesRow
    from rclverify.stages.workspace import Workspace

DIR = "artifacts/instances"
INDEX = f"{DIR}/index.json"


def _rename(text: str, names: Mapping[str, str]) -> str:
    """``text`` with each ``C.in.``/``C.out.`` (and ``C.`` before a state name) of a contract ``C``
    of ``names`` written ``names[C].``: a contract's name is a whole word followed by a dot."""
    if not names:
        return text
    pat = re.compile(r"(?<![\w.])(" + "|".join(re.escape(c) for c in sorted(names, key=len, reverse=True)) + r")\.")
    return pat.sub(lambda m: names[m.group(1)] + ".", text)


def _for_namespace(req: "Requirement", plan: "Plan", names: Mapping[str, str], ns: str) -> tuple["Requirement", "Plan"]:
    """``req`` and ``plan`` for the namespace ``ns``: the statements renamed (:func:`_rename`), the
    support rows, facts and state declarations of each contract given to its instance."""
    def src(s: Any) -> Any:
        return None if s is None else dataclasses.replace(s, text=_rename(s.text, names))
    r = dataclasses.replace(
        req, id=f"{req.id}[{ns}]", formal=src(req.formal), assuming=tuple(src(a) for a in req.assuming),
        ranking=src(req.ranking), invariant=src(req.invariant),
        support=tuple(dataclasses.replace(s, node=names.get(s.node, s.node)) for s in req.support))
    facts = {**plan.facts, **{i: plan.facts[c] for c, i in names.items() if c in plan.facts}}
    states = tuple(plan.states) + tuple(dataclasses.replace(s, node=names[s.node]) for s in plan.states
                                        if s.node in names)
    return r, dataclasses.replace(plan, facts=facts, states=states)


def _mentioned(req: "Requirement", contracts: Sequence[str]) -> list[str]:
    """The instanced ``contracts`` the statements of ``req`` name (``C.in.``/``C.out.``/``C.``)."""
    texts = " ".join(s.text for s in (req.formal, *req.assuming, req.ranking, req.invariant) if s is not None)
    return [c for c in contracts if re.search(r"(?<![\w.])" + re.escape(c) + r"\.", texts)]


def _decide(req: "Requirement", plan: "Plan", inst_checked: Any, model: Any,
            instances: Mapping[str, Sequence["Instance"]]) -> list[dict[str, Any]]:
    """The per-namespace verdicts of ``req`` (module docstring); ``[]`` when it names no instanced contract."""
    from rclverify.calculus.requirements.check import check_requirement  # deferred: loads z3 and the calculus
    from rclverify.lang.errors import RclError  # deferred: as above
    from rclverify.semantics.world import fresh  # deferred: as above
    named = _mentioned(req, [c for c, insts in instances.items() if insts])
    spaces = sorted({i.namespace for c in named for i in instances[c]})
    out: list[dict[str, Any]] = []
    for ns in spaces:
        names = {c: i.name for c in named for i in instances[c] if i.namespace == ns}
        row: dict[str, Any] = {"id": req.id, "namespace": ns, "nodes": dict(sorted(names.items()))}
        missing = [c for c in named if c not in names]
        if missing:
            out.append({**row, "verdict": "inconclusive", "missing": missing,
                        "reason": f"{', '.join(missing)} has no instance in {ns}: the statement cannot be "
                                  f"asked of the robot in {ns}"})
            continue
        r, p = _for_namespace(req, plan, names, ns)
        fresh()  # each check in the same Z3 state whatever ran before it (semantics/world.py)
        try:
            rec = check_requirement(r, inst_checked, model, p)
        except RclError as exc:
            out.append({**row, "verdict": "error", "reason": str(exc)})
            continue
        cone = set(rec.get("cone") or ())
        unfed = [f"{n}.in.{v}" for n, v, _t in model.env_inputs if n in cone]
        keep = {"unfed": unfed} if unfed and rec["verdict"] != "proved" else {}
        keep |= {k: rec[k] for k in ("formal", "cone", "counterexample", "failed_to_prevent", "reason", "explanation")
                if rec.get(k) is not None}
        out.append({**row, "verdict": rec["verdict"], **keep})
    return out


def _instance_rows(plan: "Plan", checked: Any, inst_checked: Any, model: Any) -> list[dict[str, Any]]:
    """Each instance's row (module docstring)."""
    feeds = {(l.to_node, l.to_var): l for l in model.links}
    rows = []
    for contract, insts in plan.node_instances.items():
        cn = checked.nodes.get(contract)
        for i in insts:
            icn = inst_checked.nodes.get(i.name)
            if cn is None or icn is None:
                continue
            names = [{"name": a.field, "resolved": b.field, "type": a.msg_type}
                     for a, b in zip(cn.node.topics, icn.node.topics)]
            names += [{"name": a.name, "resolved": b.name, "type": f"{a.kind} {a.ros_type}"} for a, b in zip(cn.node.links, icn.node.links)]
            inputs = []
            for var in icn.inputs:
                l = feeds.get((i.name, var))
                inputs.append({"var": var, "source": None if l is None else f"{l.from_node}.out.{l.from_var}",
                               "via": None if l is None else l.via})
            rows.append({"node": i.name, "contract": contract, "namespace": i.namespace, "ros_node": i.fqn,
                         "source": f"{i.loc.file}:{i.loc.line}:{i.loc.col}", "names": names, "inputs": inputs})
    return rows


def _files(ws: "Workspace") -> list[str]:
    return sorted({ws.plan.file, *ws.plan.contracts})


def stage_instances(ws: "Workspace") -> dict[str, Any] | None:
    """Write the stage's sealed record (module docstring) and return it; ``None``, and the record
    removed, for a plan without instances.  Raises what the system model raises (an ambiguous input,
    located ``RclError``), :class:`~rclverify.model.names.BadName` (the plan's reference check
    refuses such a name first) and ``OSError`` when the record cannot be written."""
    plan = ws.plan
    path = ws.root / INDEX
    if not any(plan.node_instances.values()):
        path.unlink(missing_ok=True)
        return None
    from rclverify.model.instances import fleet_system  # deferred: only a plan with instances
    from rclverify.model.plan.load import all_requirements  # deferred: start-up
    checked = ws.checked
    inst_checked, model = fleet_system(checked, plan.node_instances, plan.connections)
    reqs = [row for req in all_requirements(plan) if req.formal is not None
            for row in _decide(req, plan, inst_checked, model, plan.node_instances)]
    record = {"instances": _instance_rows(plan, checked, inst_checked, model), "requirements": reqs,
              "environment_inputs": [{"node": n, "var": v, "type": t} for n, v, t in model.env_inputs],
              "inputs": hash_inputs(ws.root, _files(ws))}
    write_sealed(path, record)
    return record


def read_instances(ws: "Workspace") -> dict[str, Any] | None:
    """The stage's record as the report may show it: ``None`` when there is none; with ``altered``
    (why its seal does not hold: nothing of it shown) or ``stale`` (made from other files than the
    current plan and contracts) set when so."""
    rec, problem = read_sealed(ws.root / INDEX, "instances record")
    if rec is None and not problem:
        return None
    if problem or rec is None:
        return {"instances": [], "requirements": [], "environment_inputs": [], "inputs": {}, "altered": problem}
    raw = rec.get("inputs")
    made: dict[str, str] = raw if isinstance(raw, dict) else {}
    now = hash_inputs(ws.root, sorted(set(made) | set(_files(ws))))
    if now != made:
        rec["stale"] = f"{INDEX} was made from another text of the plan or contracts: run the requirements task again"
    return rec


def instances_row(ws: "Workspace", obligations: Sequence[Mapping[str, Any]]) -> InstancesRow | None:
    """The report's ``instances`` (:func:`read_instances`) as an
    :class:`~rclverify.records.instance_rows.InstancesRow`, each instance given the obligations of its
    contract with their current status (``obligations``: the report's rows, ``id``, ``node``,
    ``status``): one obligation, every instance, except an obligation of one instance (the monitors
    judge a recorded run per instance: its id ends ``_<instance>``, ``Guard.g0.monitors.fleet_jsonl_Guard_r1``),
    listed at that instance only; ``None`` for a plan without instances.  Raises
    :class:`msgspec.ValidationError` for a record of another shape (a bug: the stage seals what it writes)."""
    rec = read_instances(ws)
    if rec is None:
        return None
    by_node: dict[str, list[dict[str, str]]] = {}
    for o in obligations:
        by_node.setdefault(str(o["node"]), []).append({"id": str(o["id"]), "status": str(o["status"])})
    # an obligation of one instance (the monitors' per-instance runs, ids ending ``_<instance>``) is that
    # instance's only: its contract's other instances do not list it
    names = {str(i["node"]) for i in rec["instances"]}
    rec["instances"] = [{**i, "obligations": [o for o in by_node.get(i["contract"], [])
                                              if not any(o["id"].endswith("_" + n) for n in names - {i["node"]})]}
                        for i in rec["instances"]]
    from rclverify.records.instance_rows import InstancesRow  # deferred: only a plan with instances
    return InstancesRow.of(rec)


def instance_problems(row: InstancesRow | Mapping[str, Any] | None) -> list[str]:
    """The report's problem sentences of ``row`` (:func:`instances_row`, or its JSON object): a stale or
    altered record, each requirement not proved in a namespace, with where its statement is written.
    Raises :class:`msgspec.ValidationError` for a row of another shape."""
    if row is None:
        return []
    from rclverify.records.instance_rows import InstancesRow  # deferred: only a plan with instances
    r = InstancesRow.of(row)
    out = [f"instances: {why}" for why in (r.altered, r.stale) if why]
    for q in r.requirements:
        if q.verdict != "proved":
            why = q.reason or "; ".join(
                ([f"not prevented by {', '.join(str(f.get('label', '')) for f in q.failed_to_prevent)}"]
                 if q.failed_to_prevent else [])
                + ([f"fed by no node: {', '.join(q.unfed)}"] if q.unfed else []))
            out.append(f"requirement {q.id} is {q.verdict} for the instances in {q.namespace}"
                       + (f" ({', '.join(f'{c} as {i}' for c, i in q.nodes.items())})" if q.nodes else "")
                       + (f": {why}" if why else ""))
    return out


#: A per-namespace verdict as an evidence status (records/statuses.py), for the report's overall status.
_STATUS = {"proved": "discharged", "refuted": "failed", "inconclusive": "inconclusive", "error": "error"}


def instance_statuses(row: InstancesRow | Mapping[str, Any] | None) -> list[str]:
    """The evidence statuses ``row`` (:func:`instances_row`, or its JSON object) adds to the report's overall
    status: each per-namespace verdict's (:data:`_STATUS`), ``stale`` or ``error`` for a stale or altered
    record."""
    if row is None:
        return []
    from rclverify.records.instance_rows import InstancesRow  # deferred: only a plan with instances
    r = InstancesRow.of(row)
    return ((["error"] if r.altered else []) + (["stale"] if r.stale else [])
            + [_STATUS.get(q.verdict, "error") for q in r.requirements])


def blocks_strict(row: InstancesRow | Mapping[str, Any] | None) -> bool:
    """Whether ``row`` fails ``--strict``: a requirement not proved in some namespace, or a record
    stale or altered."""
    return bool(instance_problems(row))


__all__ = ["DIR", "INDEX", "blocks_strict", "instance_problems", "instance_statuses", "instances_row", "read_instances",
           "stage_instances"]
