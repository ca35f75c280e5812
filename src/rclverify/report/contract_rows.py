"""The report's rows of the contracts: side conditions, health findings, nodes and guarantees, derived properties.

The roll-up of the paper's reading of evidence (a guarantee is established
only when every obligation for it is discharged), worst status first
(:data:`rclverify.records.records.SEVERITY`):

* guarantee: worst of its obligations (``unverified`` when it has none),
  and ``failed`` when the health checks found it vacuous or the contract
  contradictory (``inconclusive`` when they could not decide);
* node: worst of its guarantees and its side conditions;
* derived property: its derivation (worst side condition of its upstream
  cone) and its evidence (worst guarantee of the cone's nodes), report/cones.py.

Each function returns its rows and changes nothing it was given.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence, cast

from msgspec.structs import replace

from rclverify.report.diagnosis_text import natural_sorted  # p1 < p2 < p10
from rclverify.records.findings import FindingRow, HealthFinding
from rclverify.records.records import Obligation, worst
from rclverify.records.derived_rows import DerivedPropertyRow, EnvironmentAssumptionRow
from rclverify.records.node_rows import AssumptionRow, GuaranteeRow, InputRow, NodeRow, OutputRow
from rclverify.records.statuses import EvidenceStatus, HealthStatus
from rclverify.report.cones import DERIVATION, ConeEvidence
from rclverify.stages.contract_texts import ContractTexts
from rclverify.report.records import node_records
from rclverify.stages.crosscheck.apply import SecondSolver
from rclverify.stages.workspace import Workspace

#: A health finding's status as the status of the guarantee (or contract) it is about.
FINDING_AS: dict[HealthStatus, EvidenceStatus] = {"ok": "discharged", "problem": "failed", "inconclusive": "inconclusive",
               # a health warning (calculus/health/shape.py) is shown but changes no status
               "warning": "discharged",
               # made from another contract text (pipeline.stale_stages)
               "stale": "stale",
               # its record altered outside rclverify (report/records.py)
               "error": "error"}
_STALE = ("STALE: made from another text of the contracts or plan than the current one "
          "(run `doit verify`); recorded status ")


def verdict_of_status(sc: dict[str, Any]) -> dict[str, Any]:
    """``sc`` (a side-condition row) with a ``verdict`` that says its
    ``status`` (records/statuses.py, "verdict and status"): a discharged row
    keeps its verdict (``discharged`` or ``discharged in context``); a row
    made stale here or downgraded by the second solver had kept the verdict
    recorded before (``discharged``), which contradicted its status."""
    if sc.get("status") == "discharged" or sc.get("verdict") == sc.get("status"):
        return sc
    return {**sc, "verdict": sc.get("status")}


def _stale_side_condition(sc: dict[str, Any]) -> dict[str, Any]:
    if sc["status"] == "error":  # an altered record stays error
        return sc
    return {**sc, "status": "stale", "explanation": _STALE + sc["status"] + ". " + str(sc.get("explanation", ""))}


def contract_records(ws: Workspace, nodes: Sequence[str], stale: Mapping[str, set[str]],
                     second: SecondSolver) -> tuple[dict[str, dict[str, Any]], dict[str, list[FindingRow]]]:
    """``(calculus record by node, health findings by node)`` as the report
    shows them: sealed (an altered record is error, never what it says,
    report/records.py), ``stale`` (node -> the stages made from another
    contract text) applied, and the second solver's verdicts folded in
    (each finding a :class:`~rclverify.records.findings.FindingRow`)."""
    comps, health = node_records(ws, nodes)
    for n, stages in stale.items():  # never the status of an old contract text
        if "compose" in stages:
            comps[n] = {**comps[n], "side_conditions": [_stale_side_condition(sc)
                                                        for sc in comps[n].get("side_conditions", [])]}
        if "health" in stages:
            health[n] = [f if f.status == "error" else
                         replace(f, status="stale", message=_STALE + f.status + ". " + f.message)
                         for f in health[n]]
    rows: dict[str, list[FindingRow]] = {}
    for n in nodes:
        if comps[n]:  # {} before the calculus ran
            comps[n] = {**comps[n], "side_conditions": [verdict_of_status(second.side_condition(sc))
                                                        for sc in comps[n].get("side_conditions", [])]}
        rows[n] = [FindingRow.of(second.finding(f.to_json())) for f in health[n]]
    return comps, rows


class GuaranteeStatuses:
    """The status of each guarantee (module docstring), callable as
    ``(node, k) -> status`` (``k`` 1-based); guarantee 0 of an obligation
    is the whole contract and bears on every guarantee of its node."""

    def __init__(self, obligations: Sequence[Obligation], status: Mapping[str, str],
                 health: Mapping[str, Sequence[HealthFinding]]) -> None:
        self.by_node: dict[str, list[Obligation]] = {}  # one pass; a scan per guarantee was quadratic
        for o in obligations:
            self.by_node.setdefault(o.node, []).append(o)
        self.status, self.health = status, health

    def obligations(self, node: str, k: int) -> list[str]:
        """The ids of the obligations bearing on guarantee ``k`` of ``node``, in natural order."""
        return natural_sorted([o.id for o in self.by_node.get(node, []) if o.guarantee in (k, 0)])

    def __call__(self, node: str, k: int) -> str:
        sts = [self.status[o.id] for o in self.by_node.get(node, []) if o.guarantee in (k, 0)]
        s = worst(sts) if sts else "unverified"
        for f in self.health[node]:
            if f.guarantee in (None, k) and f.status != "ok":
                s = worst([s, FINDING_AS[f.status]])
        return s


@dataclass
class NodesPart:
    """The node rows (each a :class:`~rclverify.records.node_rows.NodeRow`) and, by node name,
    each node's status and the worst status of its guarantees."""
    nodes: list[NodeRow] = field(default_factory=list)
    status: dict[str, str] = field(default_factory=dict)
    evidence: dict[str, str] = field(default_factory=dict)


def _ports(to_node: Sequence[Any], from_node: Sequence[Any],
           tx: Mapping[str, Any]) -> tuple[list[InputRow], list[OutputRow]]:
    """A node's ``inputs`` (with the producer linked to each) and ``outputs``
    (with their consumers); ``to_node``/``from_node``: the model's links into and out of it."""
    internal = {l.to_var: f"{l.from_node}.{l.from_var}" for l in to_node}
    consumers: dict[str, list[str]] = {}
    for l in from_node:
        consumers.setdefault(l.from_var, []).append(f"{l.to_node}.{l.to_var}")
    return ([InputRow(name=v, type=t, producer=internal.get(v)) for v, t in tx["inputs"]],
            [OutputRow(name=v, type=t, consumers=consumers.get(v, [])) for v, t in tx["outputs"]])


def node_part(ws: Workspace, texts: ContractTexts, comps: Mapping[str, Mapping[str, Any]],
              g_status: GuaranteeStatuses, sc_status: Mapping[str, str]) -> NodesPart:
    """One row per node of ``ws``'s contracts: its ports, assumptions,
    guarantees with their statuses, LaTeX, and its status (module docstring)."""
    part = NodesPart()
    links_to: dict[str, list[Any]] = {}
    links_from: dict[str, list[Any]] = {}
    for l in ws.model.links:
        links_to.setdefault(l.to_node, []).append(l)
        links_from.setdefault(l.from_node, []).append(l)
    for name, cn in ws.checked.nodes.items():
        tx = texts.node(cn.node)
        env_texts = {e["text"] for e in comps[name].get("environment_assumptions", [])}
        guarantees = [GuaranteeRow(index=k, text=text, source=src, status=cast(EvidenceStatus, g_status(name, k)),
                                   obligations=g_status.obligations(name, k))
                      for k, (text, src) in enumerate(tx["guarantees"], 1)]
        status = worst([g.status for g in guarantees] + [sc_status[name]])
        part.status[name] = status
        part.evidence[name] = worst([g.status for g in guarantees], empty="pending")
        inputs, outputs = _ports(links_to.get(name, []), links_from.get(name, []), tx)
        part.nodes.append(NodeRow(
            name=name, source=str(cn.node.loc), status=cast(EvidenceStatus, status), inputs=inputs, outputs=outputs,
            assumptions=[AssumptionRow(text=text, source=src, environment=text in env_texts)
                         for text, src in tx["assumptions"]],
            guarantees=guarantees, latex=tx["latex"]))
    return part


def derived_rows(ws: Workspace, comps: Mapping[str, Mapping[str, Any]], nodes: NodesPart,
                 sc_status: Mapping[str, str]) -> list[DerivedPropertyRow]:
    """One row per node the calculus derived a property for: its rules,
    instances, the cone's environment assumptions, and its two statuses
    (derivation and evidence, report/cones.py)."""
    model = ws.model
    cones, cone_of = ConeEvidence(model.nodes, nodes.evidence, sc_status), model.upstream_masks()
    rows: list[DerivedPropertyRow] = []
    for n in ws.checked.nodes:
        c = comps[n]
        if not c:
            continue
        derivation, ev_status, ev_note = cones.summary(cone_of[n])  # the cone of the calculus (model.upstream)
        rows.append(DerivedPropertyRow(
            node=n, rules=c["rules"], instances=c["instances"],
            environment_assumptions=c["cone_environment_assumptions"], property=c["derived_property"],
            # the derivation: every side condition of the cone discharged
            status=cast(EvidenceStatus, derivation), derivation=DERIVATION.get(derivation, "undecided"),
            # what the rules' premises (the node contracts) rest on
            evidence_status=cast(EvidenceStatus, ev_status), evidence_note=ev_note,
            loop_assumption=c["loop_assumption"]))
    return rows


def environment_rows(comps: Mapping[str, Mapping[str, Any]], nodes: Sequence[str]) -> list[EnvironmentAssumptionRow]:
    """The environment assumptions of the calculus records ``comps`` (node -> record), node by node in the
    order of ``nodes``, each an :class:`~rclverify.records.derived_rows.EnvironmentAssumptionRow`
    (``KeyError`` for a record's assumption without ``node``, ``text`` or ``source``)."""
    return [EnvironmentAssumptionRow(node=str(e["node"]), text=str(e["text"]), source=str(e["source"]))
            for n in nodes for e in comps[n].get("environment_assumptions", [])]
