"""Roll the pipeline's artifacts up into the assurance report (one dict).

Traceability: requirement -> node -> guarantee -> obligation -> evidence.
Roll-up takes the worst status of the children
(:data:`rclverify.records.records.SEVERITY`); nothing is shown as verified
while any of its evidence is failed, pending, stale or missing:

* obligation: its evidence's *current* status (``stale`` when an input's
  sha256 changed since the evidence was produced), ``pending`` when there is
  no evidence record;
* guarantee: worst of its obligations (``unverified`` when it has none: no
  evidence entry of the plan exports an obligation for it; each such
  guarantee is listed under ``unverified`` and is a problem of its own), and
  ``failed`` when the health checks found it vacuous or the contract
  contradictory (``inconclusive`` when they could not decide);
* node: worst of its guarantees and its side conditions;
* requirement: worst of the guarantees that support it and of the side
  conditions of their nodes;
* derived property: two separate statuses.  Its *derivation* (``status``,
  shown as ``derived`` / ``not derived`` / ``undecided``) is the worst of the
  side conditions of the nodes in its upstream cone: the calculus derived it
  when all of them are discharged.  Its *evidence* (``evidence_status`` with
  ``evidence_note``, e.g. "rests on 1 failed node contract:
  RadiationSensor") is the worst status of those nodes' guarantees: the
  rules' premises are the node contracts, which only evidence establishes.
"""
from __future__ import annotations

from functools import reduce
from operator import or_
from typing import Any, Iterable, Mapping, Sequence

import z3

from rclverify import __version__
from rclverify.report.contract_texts import ContractTexts
from rclverify.records.records import SEVERITY, Obligation, worst
from rclverify.records.statuses import Derivation, EvidenceStatus, HealthStatus
from rclverify.records.store import EvidenceStore
from rclverify.stages.workspace import Workspace, current_snapshot_hashes, stale_stages
from rclverify.model.system.model import cycles_kept, names_of
from rclverify.diagnosis.build import diagnose
from rclverify.diagnosis.text import natural_sorted  # p1 < p2 < p10
from rclverify.report.expected import expected_rows
from rclverify.records.report_schema import Report, as_report
from rclverify.report.statistics import annotate_statistics, compact as compact_statistics
from rclverify.report.records import diagnostics as read_diagnostics, grounding as read_grounding, inputs_sha256, node_obligations, \
    node_records

_FINDING_AS: dict[HealthStatus, EvidenceStatus] = {"ok": "discharged", "problem": "failed", "inconclusive": "inconclusive",
               # a health warning (calculus/health/shape.py) is shown but changes no status
               "warning": "discharged",
               # made from another contract text (pipeline.stale_stages)
               "stale": "stale",
               # its record altered outside rclverify (report/records.py)
               "error": "error"}


def _brief(text: str, limit: int = 300) -> str:
    """``text`` cut to at most ``limit`` characters at a word boundary, with
    an ellipsis and a pointer to the full record when it was cut."""
    if len(text) <= limit:
        return text
    cut = text[:limit].rsplit(" ", 1)[0].rstrip(" ,;:")
    return cut + " ... (in full in the evidence record)"


def _evidence_extras(ws: Workspace, details: Any) -> dict[str, Any]:
    """Rows a backend asks the report to show (``details.figures_table``: the
    experiment figures, the review record) and the inline SVG of its plot
    (``details.plot``, an SVG artifact the backend drew with matplotlib)."""
    out: dict[str, Any] = {}
    rows = details.get("figures_table") if isinstance(details, dict) else None
    if rows:
        out["figures"] = [[str(a), str(b)] for a, b in rows]
    plot = details.get("plot") if isinstance(details, dict) else None
    if isinstance(plot, str) and plot.endswith(".svg"):
        try:
            text = ws.path(plot).read_text(encoding="utf-8")
            out["plot_svg"] = text[text.index("<svg"):]
        except (OSError, ValueError):
            pass
    return out


_DERIVATION: dict[str, Derivation] = {"discharged": "derived", "failed": "not derived"}
#: Most node names a derived property's note lists per status ("3 pending node contracts: A, B, C");
#: the rest are counted.  A property at the end of a 1000-node chain rests on 999 contracts: its
#: note named them all, a quadratic amount of report text nobody reads (the cone itself is the
#: system model's: ``SystemModel.upstream``).
CONE_NAMES = 10


class ConeEvidence:
    """The derivation status and the evidence status and note of the cones
    of one system: the note says which node contracts a derived property
    rests on that are not yet established ("rests on 1 failed node
    contract: RadiationSensor"), at most :data:`CONE_NAMES` per status.

    The cones of a 1000-node chain hold half a million names; grouping them
    name by name took 0.3-0.5 s of every report build (docs/scale.md,
    seventh round).  Here a cone is a bit mask over the system's nodes
    (``order``; :meth:`rclverify.model.system.model.SystemModel.upstream_masks`)
    and so is each status, so a cone's count per status is a popcount and
    the first :data:`CONE_NAMES` names of a status are its lowest bits.

    ``node_evidence`` maps node names to evidence statuses (the worst of a
    node's guarantees); ``side_conditions`` maps them to the worst status
    of their side conditions.  A node of ``order`` that either lacks is
    ``pending`` there.
    """

    def __init__(self, order: Sequence[str], node_evidence: Mapping[str, str],
                 side_conditions: Mapping[str, str] | None = None) -> None:
        self.order = list(order)
        self.bit = {n: 1 << i for i, n in enumerate(self.order)}
        self.evidence_masks = self._masks(node_evidence)
        self.side_condition_masks = self._masks(side_conditions or {})

    def _masks(self, statuses: Mapping[str, str]) -> dict[str, int]:
        masks: dict[str, int] = {}
        for n, b in self.bit.items():
            st = statuses.get(n, "pending")
            masks[st] = masks.get(st, 0) | b
        return masks

    def mask(self, cone: Iterable[str]) -> int:
        """The bit mask of the nodes ``cone`` names (``KeyError`` for a node not in ``order``)."""
        return reduce(or_, map(self.bit.__getitem__, cone), 0)

    def summary(self, mask: int) -> tuple[str, str, str]:
        """(worst side-condition status of the nodes of the cone ``mask`` --
        its derivation, ``discharged`` for an empty cone --, their worst
        evidence status, the evidence note)."""
        if not mask:
            return "discharged", "discharged", "derived; rests on no node contract"
        derivation = worst([st for st, m in self.side_condition_masks.items() if mask & m])
        counts = {st: (mask & m).bit_count() for st, m in self.evidence_masks.items() if mask & m}
        if counts.keys() == {"discharged"}:
            return derivation, "discharged", "every node contract it rests on is discharged"
        parts = []
        for st in sorted(counts, key=lambda x: -SEVERITY.get(x, 0)):
            if st == "discharged":
                continue
            n = counts[st]
            named = names_of(mask & self.evidence_masks[st], self.order, CONE_NAMES)  # the first in system order
            more = f" and {n - CONE_NAMES} more" if n > CONE_NAMES else ""
            parts.append(f"{n} {st} node contract{'s' if n != 1 else ''}: {', '.join(named)}{more}")
        return derivation, worst(list(counts)), "rests on " + "; ".join(parts)


def build_report(ws: Workspace) -> Report:
    """Read every artifact of ``ws`` and return the report (see render.py): a
    :class:`.schema_types.Report`, the shape docs/assurance.schema.json publishes."""
    checked, model, plan = ws.checked, ws.model, ws.plan
    texts = ContractTexts(ws)  # each node's RCL and LaTeX texts, kept by its file's sha256 (read only here)
    store = EvidenceStore(ws.root)
    obligations: list[Obligation] = []
    altered_lists: dict[str, str] = {}  # placeholder obligation id -> why its node's list is not believed
    for n in checked.nodes:
        obs, why = node_obligations(ws, n)  # sealed: a list altered outside rclverify is one error row
        obligations.extend(obs)
        if why:
            altered_lists[obs[0].id] = why
    ev_rows: list[dict[str, Any]] = []
    ob_rows: list[dict[str, Any]] = []
    pending: list[dict[str, Any]] = []
    ob_status: dict[str, str] = {}
    declared: dict[str, list[tuple[str, Any]]] = {}  # node -> (record status, declaration rows) per record
    problems_altered: list[str] = []  # records that cannot be read as rclverify wrote them
    # input sha256s, taken once per file: nothing changes while the report is built.  Each node's
    # snapshot is taken from the current contracts and plan, not from artifacts/contracts/, so
    # evidence of another contract text is stale even when no check ran since the edit.
    hashes: dict[str, str] = current_snapshot_hashes(ws, texts)  # the model's too
    made_from, ev_inputs = dict(hashes), dict[str, Any]()  # what the report is built from (meta.inputs_sha256)
    stale = stale_stages(ws, hashes)  # calculus or health made from another contract text
    from rclverify.stages.crosscheck.apply import load as load_second_solver
    second = load_second_solver(ws.root)  # cvc5's verdicts: a proof the two solvers do not agree on is inconclusive
    for o in obligations:
        ev, altered = (None, altered_lists[o.id]) if o.id in altered_lists else store.read(o.id)
        ev_inputs[o.id] = dict(ev.input_hashes) if ev is not None else None
        if altered:
            status = "error"
        else:
            status = store.current_status(ev, hashes) if ev else "pending"
        status, solvers = second.evidence(o.id, o.backend, status)
        ob_status[o.id] = status
        ob_rows.append({"id": o.id, "node": o.node, "guarantee": o.guarantee, "backend": o.backend, "kind": o.kind,
                        "instance": o.instance, "statement": o.statement, "source": str(o.source),
                        "artifact": o.artifact, "status": status})
        if ev is None:
            if altered:
                problems_altered.append(f"Evidence {o.id} is error: {altered}")
                continue
            pending.append({"obligation": o.id, "backend": o.backend, "reason": "no evidence record yet: run `doit verify`"})
            continue
        if isinstance(ev.details.get("declarations"), list):  # a node's declarations judged (issue 64)
            declared.setdefault(o.node, []).append((status, ev.details["declarations"]))
        expl = ev.explanation
        if altered:
            expl = f"{altered[0].upper()}{altered[1:]}. The record's own text follows, not to be believed: " + expl
        if solvers is not None and status != ev.status:
            expl = f"Not discharged: {solvers['why']} (second solver). Z3 alone: " + expl
        if status == "stale" and ev.status != "stale":
            expl = f"STALE: an input changed since this evidence was produced (recorded status {ev.status}). " + expl
        ev_rows.append({"obligation": ev.obligation, "backend": ev.backend, "kind": ev.kind, "status": status,
                        "tool": ev.tool, "tool_version": ev.tool_version, "started": ev.started,
                        "duration_s": ev.duration_s, "explanation": expl, "counterexample": ev.counterexample,
                        "artifacts": list(ev.artifacts), "log_excerpt": ev.log[-2000:],
                        **_evidence_extras(ws, ev.details)})
        if solvers is not None:
            ev_rows[-1]["solvers"] = solvers
        if isinstance(ev.details.get("examples"), dict):  # property tests: example counts and seed
            ev_rows[-1]["examples"] = {**ev.details["examples"], "seed": ev.details.get("seed"),
                                       "replay": ev.details.get("replay", ""),
                                       "facts": ev.details.get("facts", []),
                                       "coverage": ev.details.get("coverage") or {}}
        if isinstance(ev.details, dict) and ev.details.get("monitoring"):
            ev_rows[-1]["monitoring"] = ev.details["monitoring"]
        if isinstance(ev.details, dict) and isinstance(ev.details.get("statistics"), dict):  # runs counted (issue 68)
            ev_rows[-1]["statistics"] = compact_statistics(ev.details["statistics"])
        if status == "pending":
            pending.append({"obligation": o.id, "backend": o.backend, "reason": ev.explanation})

    expected = expected_rows(plan, ob_rows)
    comps, health = node_records(ws, checked.nodes)  # sealed: an altered record is error, never what it says
    for n, stages in stale.items():  # never the status of an old contract text
        note = ("STALE: made from another text of the contracts or plan than the current one "
                "(run `doit verify`); recorded status ")
        if "compose" in stages:
            comps[n] = {**comps[n], "side_conditions": [
                sc if sc["status"] == "error" else  # an altered record stays error
                {**sc, "status": "stale", "explanation": note + sc["status"] + ". " + str(sc.get("explanation", ""))}
                for sc in comps[n].get("side_conditions", [])]}
        if "health" in stages:
            health[n] = [f if f["status"] == "error" else
                         {**f, "status": "stale", "message": note + f["status"] + ". " + f["message"]}
                         for f in health[n]]
    for n in checked.nodes:
        if comps[n]:  # {} before the calculus ran
            comps[n] = {**comps[n], "side_conditions": [_verdict_of_status(second.side_condition(sc))
                                                        for sc in comps[n].get("side_conditions", [])]}
        health[n] = [second.finding(f) for f in health[n]]
    # a counterexample shows the nodes involved only: the consumer and the producers of the linked variables
    side_conditions = [involved_model(sc) for n in checked.nodes for sc in comps[n].get("side_conditions", [])]
    sc_status = {n: worst([sc["status"] for sc in comps[n].get("side_conditions", [])], empty="discharged")
                 for n in checked.nodes}

    def applies(o: Obligation, node: str, k: int) -> bool:
        """Obligation ``o`` bears on guarantee ``k`` of ``node`` (guarantee 0: the whole contract)."""
        return o.node == node and o.guarantee in (k, 0)

    by_node: dict[str, list[Obligation]] = {}  # one pass; a scan per guarantee was quadratic in the system size
    for o in obligations:
        by_node.setdefault(o.node, []).append(o)
    links_to: dict[str, list[Any]] = {}
    links_from: dict[str, list[Any]] = {}
    for l in model.links:
        links_to.setdefault(l.to_node, []).append(l)
        links_from.setdefault(l.from_node, []).append(l)

    def g_status(node: str, k: int) -> str:
        sts = [ob_status[o.id] for o in by_node.get(node, []) if applies(o, node, k)]
        s = worst(sts) if sts else "unverified"
        for f in health[node]:
            if f["guarantee"] in (None, k) and f["status"] != "ok":
                s = worst([s, _FINDING_AS[f["status"]]])
        return s

    nodes = []
    node_status: dict[str, str] = {}
    node_evidence: dict[str, str] = {}
    for name, cn in checked.nodes.items():
        internal = {l.to_var: f"{l.from_node}.{l.from_var}" for l in links_to.get(name, [])}
        consumers: dict[str, list[str]] = {}
        for l in links_from.get(name, []):
            if l.from_node == name:
                consumers.setdefault(l.from_var, []).append(f"{l.to_node}.{l.to_var}")
        env_texts = {e["text"] for e in comps[name].get("environment_assumptions", [])}
        tx = texts.node(cn.node)
        guarantees: list[dict[str, Any]] = [
            {"index": k, "text": text, "source": src, "status": g_status(name, k),
             "obligations": natural_sorted([o.id for o in by_node.get(name, []) if applies(o, name, k)])}
            for k, (text, src) in enumerate(tx["guarantees"], 1)]
        status = worst([g["status"] for g in guarantees] + [sc_status[name]])
        node_status[name] = status
        node_evidence[name] = worst([g["status"] for g in guarantees], empty="pending")
        nodes.append({
            "name": name, "source": str(cn.node.loc), "status": status,
            "inputs": [{"name": v, "type": t, "producer": internal.get(v)} for v, t in tx["inputs"]],
            "outputs": [{"name": v, "type": t, "consumers": consumers.get(v, [])} for v, t in tx["outputs"]],
            "assumptions": [{"text": text, "source": src, "environment": text in env_texts}
                            for text, src in tx["assumptions"]],
            "guarantees": guarantees, "latex": tx["latex"],
        })

    from rclverify.report.unverified import unverified_guarantees
    unverified = unverified_guarantees(plan, nodes)

    requirements: list[dict[str, Any]] = []
    from rclverify.model.plan.load import all_requirements
    from rclverify.stages.requirements import read_records
    from rclverify.calculus.requirements.rollup import declaration_statuses
    checks = read_records(ws, hashes)  # sealed and hashed: altered -> error, other inputs -> stale
    checks = {k: second.requirement(v) or v for k, v in checks.items()}
    for r in all_requirements(plan):
        support: list[dict[str, Any]] = []
        for s in r.support:
            for k in s.guarantees:
                text, src = texts.node(checked.nodes[s.node].node)["guarantees"][k - 1]
                support.append({"node": s.node, "guarantee": k, "text": text, "source": src,
                                "status": g_status(s.node, k),
                                "obligations": natural_sorted([o.id for o in obligations if applies(o, s.node, k)])})
        st = worst([x["status"] for x in support] + [sc_status[x["node"]] for x in support]) if support else "pending"
        requirements.append({"id": r.id, "text": r.text, "status": st, "support": support,
                             **requirement_check(current_record(r, checks.get(r.id)), st, g_status, sc_status,
                                                 declaration_statuses(declared, checked))})

    from rclverify.report.deadlines import deadline_rows, fold_into, strict_ok as deadlines_ok
    deadlines = deadline_rows(ws, hashes, g_status, ob_rows, second)  # rule D3, rolled into each requirement
    fold_into(requirements, deadlines)

    derived = []
    cones, cone_of = ConeEvidence(model.nodes, node_evidence, sc_status), model.upstream_masks()
    for n in checked.nodes:
        c = comps[n]
        if not c:
            continue
        derivation, ev_status, ev_note = cones.summary(cone_of[n])  # the cone of the calculus (model.upstream)
        derived.append({"node": n, "rules": c["rules"], "instances": c["instances"],
                        "environment_assumptions": c["cone_environment_assumptions"], "property": c["derived_property"],
                        # the derivation: every side condition of the cone discharged
                        "status": derivation, "derivation": _DERIVATION.get(derivation, "undecided"),
                        # what the rules' premises (the node contracts) rest on
                        "evidence_status": ev_status, "evidence_note": ev_note,
                        "loop_assumption": c["loop_assumption"]})

    findings = [f for n in checked.nodes for f in health[n]]
    from rclverify.calculus.scale import scale_findings  # a side condition's ranges a power of ten apart (a warning)
    findings += scale_findings(side_conditions)
    lint_rows = [{"severity": d["severity"], "location": f"{d['file']}:{d['line']}:{d['col']}", "message": d["message"],
                  "code": d.get("code", "")}
                 for d in read_diagnostics(ws)]
    env_assumptions = [e for n in checked.nodes for e in comps[n].get("environment_assumptions", [])]
    from rclverify.model.plan.acknowledged import apply_acknowledgements  # warnings answered in the plan (docs/plan.md, issue 64)
    acknowledgements = apply_acknowledgements(plan.acknowledged, findings, lint_rows, checked)

    problems = []
    for f in findings:
        if f["status"] == "problem":
            problems.append(f"Contract health: {f['message']}")
        elif f["status"] == "error":
            problems.append(f"Contract health of {f['node']} is error: {f['message']}")
        elif f["status"] == "stale":
            problems.append(f"Contract health of {f['node']} is stale: made for another text of its contract or plan "
                            "(run `doit verify`)")
    for rq in requirements:
        if rq["verdict"] in ("refuted", "proved from an inconsistency", "proved vacuously", "error", "stale"):
            problems.append(f"Requirement {rq['id']} is {rq['verdict']}: {_brief(rq['note'])}")
    for sc in side_conditions:
        if sc["status"] != "discharged":
            where = " (checked in context too)" if sc.get("context") and sc["status"] != "stale" else ""
            problems.append(f"Side condition {sc['id']} is {sc['status']}{where}: {sc['conjunct']}")
    problems.extend(problems_altered)
    problems.extend(f"Acknowledgement {a['at']} is {a['status']}: {a['message']}" for a in acknowledgements
                    if a["status"] != "ok")
    problems.extend(u["message"] for u in unverified)
    for e in ev_rows:
        if e["status"] in ("failed", "error", "stale"):
            problems.append(f"Evidence {e['obligation']} is {e['status']}: {_brief(e['explanation'])}")
    for x in expected:
        if x["outcome"] == "MISMATCH":
            problems.append(f"Expected verdict mismatch: {x['obligation']} is {x['actual']}, the plan expects "
                            f"{x['expected']} ({x['source']})" + (f": {x['reason']}" if x["reason"] else ""))
    counts: dict[str, int] = {}
    for row in ob_rows:
        counts[row["status"]] = counts.get(row["status"], 0) + 1
    overall = worst([r["status"] for r in requirements] + list(node_status.values()) + [d["status"] for d in derived])
    # the --strict gate: every obligation discharged, every side condition proved,
    # and no health check that found a problem or could not decide (and, below, no finding of severity
    # error or warning at all: report/severity.py)
    strict_ok = (all(o["status"] == "discharged" for o in ob_rows)
                 and all(sc["status"] == "discharged" for sc in side_conditions)
                 and all(f["status"] in ("ok", "warning") for f in findings)
                 # and no guarantee left without evidence (no obligation exported for it)
                 and all(g_status(name, k) == "discharged" for name, cn in checked.nodes.items()
                         for k in range(1, len(cn.node.guarantees) + 1))
                 # and every formal requirement met (docs/requirements.md, "--strict"); an informal one is listed only
                 and all(rq["verdict"] in ("met", "informal") for rq in requirements)
                 and deadlines_ok(deadlines))  # and every end-to-end deadline proved
    # grounding in the robot's software (docs/ros.md): findings never change a verdict,
    # but a grounding error fails --strict and is listed among the problems
    grounding = read_grounding(ws, "artifacts/ros/grounding.json") if getattr(plan, "ros", None) else None
    if grounding is not None:
        svg_rel = (grounding.get("drawing") or {}).get("svg")
        try:
            grounding["svg_text"] = ws.path(svg_rel).read_text(encoding="utf-8") if svg_rel else None
        except OSError:
            grounding["svg_text"] = None
        strict_ok = strict_ok and not grounding["counts"]["error"] and not grounding.get("stale")
        if grounding.get("stale"):
            problems.append(f"Grounding is stale: {grounding['stale']}")
        if grounding["counts"]["error"]:
            problems.append(f"Grounding: {grounding['counts']['error']} contract(s)-vs-ROS error(s) "
                            f"(rclverify ros check)")
    headline = _headline(ob_rows, counts, side_conditions, findings, unverified)
    system = model.view(node_status, cycles_kept(model, ws.path("artifacts/cache/system-cycles.pickle")))
    report: dict[str, Any] = {
        "meta": {"tool": "rclverify", "version": __version__, "workspace": plan.name or ws.root.resolve().name, "plan": plan.file,
                 "contracts": list(plan.contracts), "z3_version": z3.get_version_string(), "strict_ok": strict_ok,
                 "inputs_sha256": inputs_sha256(ws, made_from, ev_inputs, checks)},
        "summary": {"status": overall, "counts": counts, "headline": headline, "problems": problems},
        "system": system, "requirements": requirements, "nodes": nodes, "side_conditions": side_conditions,
        "derived_properties": derived, "findings": findings, "obligations": ob_rows, "evidence": ev_rows,
        "environment_assumptions": env_assumptions, "pending": pending, "lint": lint_rows,
        "expected_verdicts": expected, "grounding": grounding, "unverified": unverified, "deadlines": deadlines,
        "acknowledgements": acknowledgements,
    }
    # runs counted by environment, bounds and targets (report/statistics.py, docs/statistics.md), before the confidence
    report["statistics"] = annotate_statistics(report, plan, {r.id: r.target for r in all_requirements(plan)})
    from rclverify.report.confidence_rows import annotate  # evidence strength and confidence over the argument (issue 50)
    report["summary"]["solvers"] = second.counts()  # how many items two solvers, one solver, ... (issue 50)
    if second.problem:
        report["summary"]["problems"].append(f"Second-solver record: {second.problem}")
    strength_ok = annotate(report, [(l.from_node, l.to_node) for l in model.links],
                           {r.id: r.strength for r in all_requirements(plan) if r.strength})
    # one severity per finding (report/severity.py): --strict fails on every error and warning, health and lint
    # warnings included, as SARIF, JUnit and the terminal show them
    from rclverify.report.severity import blocking
    report["meta"]["strict_ok"] = bool(strict_ok) and strength_ok and not second.problem and not blocking(report)
    # one diagnosis record per problem, with repairs checked by Z3 (docs/diagnosis.md)
    report["diagnoses"] = diagnose(ws, report)
    report["summary"]["diagnoses"] = [{"id": d["id"], "kind": d["kind"], "sentence": d["sentence"],
                                       "repairs": len(d["repairs"])} for d in report["diagnoses"]]
    # the problems grouped by root cause: one row per culprit (report/problems.py, docs/reading-the-report.md)
    from rclverify.report.problems import group_problems
    from rclverify.report.render import anchor, problem_items
    report["problems"] = group_problems(report, problem_items(report), anchor)
    from rclverify.report.culprits import mark_culprits  # a culprit node reads its problem's status, never "discharged" (issue 64)
    mark_culprits(report)
    return as_report(report)


def _verdict_of_status(sc: dict[str, Any]) -> dict[str, Any]:
    """``sc`` (a side-condition row) with a ``verdict`` that says its
    ``status``: a discharged row keeps its verdict (``discharged`` or
    ``discharged in context``); a row made stale here or downgraded by the
    second solver had kept the verdict recorded before (``discharged``),
    which contradicted its status (docs/reading-the-report.md, "The report's
    schema")."""
    if sc.get("status") == "discharged" or sc.get("verdict") == sc.get("status"):
        return sc
    return {**sc, "verdict": sc.get("status")}


def involved_model(sc: Mapping[str, Any]) -> Mapping[str, Any]:
    """``sc`` (a side-condition row of the calculus) with its Z3 ``model``
    cut to the nodes its conjunct involves (:func:`.cex_cone.side_condition_view`:
    the consumer, the producers of its links and, decided in context, the
    nodes whose assumption the counterexample violates)."""
    from rclverify.report.cex_cone import side_condition_view
    return side_condition_view(sc)


#: The fields of a requirement's check record (calculus/requirements/check.py) the report carries.
_CHECK_FIELDS = ("origin", "source", "formal", "assuming", "cone", "used", "traced_not_needed", "consistency",
                 "inconsistent_core", "vacuity", "vacuity_core", "counterexample", "outside_assumptions",
                 "counterexample_note", "failed_to_prevent", "reason", "smt2", "explanation",
                 "solvers",  # the second solver's agreement (stages/crosscheck/apply.py)
                 "consistency_smt2", "consistency_solvers", "recorded_consistency",  # and on the side queries
                 "vacuity_smt2", "vacuity_solvers", "recorded_vacuity",
                 "temporal",  # a temporal requirement's verdict, k, bound and trace (calculus/requirements/temporal_check.py)
                 "traces",  # its recorded runs' verdicts (backends/monitors/temporal_evidence.py)
                 "duration_s")


def current_record(req: Any, record: Mapping[str, Any] | None) -> Mapping[str, Any] | None:
    """``record`` when it was made from ``req``'s current statements (else
    ``None``: not checked yet, e.g. ``rclverify report`` after a plan edit,
    before the ``requirements`` stage ran); an informal requirement needs no
    record."""
    formal = " ".join(req.formal.text.split()) if req.formal else None
    hints = [" ".join(x.text.split()) if x else None for x in (getattr(req, "ranking", None),
                                                                 getattr(req, "invariant", None))]
    if record is not None and record.get("formal") == formal \
            and record.get("assuming", []) == [" ".join(a.text.split()) for a in req.assuming] \
            and [record.get("ranking"), record.get("invariant")] == hints:
        return record
    if formal is None:
        return {"verdict": "informal", "source": f"{req.loc.file}:{req.loc.line}:{req.loc.col}", "origin": req.origin}
    return None


def requirement_check(record: Mapping[str, Any] | None, traced_status: str, g_status: Any,
                      sc_status: Mapping[str, str], d_status: Any = None) -> dict[str, Any]:
    """The requirement row's fields from its Z3 check: ``verdict`` (met /
    proved, evidence outstanding / proved from an inconsistency / refuted /
    inconclusive / informal), ``status`` (only ``met`` is ``discharged``),
    ``note`` and the check's details (:mod:`rclverify.calculus.requirements.rollup`)."""
    from rclverify.calculus.requirements.rollup import roll_up
    verdict, status, note = roll_up(record, g_status, sc_status, traced_status, d_status)
    from rclverify.report.cex_cone import with_trace_view  # a temporal trace cut to what matters (issue 48)
    details = dict(with_trace_view({k: (record or {}).get(k) for k in _CHECK_FIELDS}))
    from rclverify.calculus.requirements.rollup import declaration_evidence  # the declarations it used, with their evidence (issue 64)
    details["declarations"] = declaration_evidence(record, d_status)
    return {"status": status, "verdict": verdict, "note": note, "check": details}


def _headline(ob_rows: list[dict[str, Any]], counts: dict[str, int], side_conditions: Sequence[Mapping[str, Any]],
              findings: list[dict[str, Any]], unverified: Sequence[Mapping[str, Any]] = ()) -> str:
    """The one-line summary, without empty fragments: a kind with nothing
    in it is said in words ("no obligations"), never as "0 obligations: ;".
    Guarantees no obligation covers (``unverified``) are counted after the
    obligations: "5 obligations: 5 discharged" alone would read as all done."""
    parts = []
    if ob_rows:
        parts.append(f"{len(ob_rows)} obligation{'s' if len(ob_rows) != 1 else ''}: "
                     + ", ".join(f"{counts[s]} {s}" for s in sorted(counts, key=lambda x: SEVERITY.get(x, 99))))
    else:
        parts.append("no obligations")
    if unverified:
        parts.append(f"{len(unverified)} guarantee{'s' if len(unverified) != 1 else ''} unverified "
                     "(no obligation covers " + ("it" if len(unverified) == 1 else "them") + ")")
    if side_conditions:
        in_context = sum(1 for sc in side_conditions if sc["status"] == "discharged"
                         and sc.get("verdict") == "discharged in context")
        parts.append(f"{sum(1 for sc in side_conditions if sc['status'] == 'discharged')}/{len(side_conditions)} "
                     "side conditions discharged" + (f" ({in_context} in context)" if in_context else ""))
    else:
        parts.append("no side conditions")
    problems = sum(1 for f in findings if f["status"] == "problem")
    parts.append(f"{problems} contract health problem{'s' if problems != 1 else ''}" if problems
                 else "no contract health problem")
    altered = sum(1 for f in findings if f["status"] == "error")
    if altered:
        parts.append(f"{altered} contract health record{'s' if altered != 1 else ''} altered outside rclverify")
    return "; ".join(parts) + "."
