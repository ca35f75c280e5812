"""The diagnosis record of a refuted requirement (docs/diagnosis.md, "Who
is named"): the guarantee whose bound lets Z3's counterexample through,
found by :func:`rclverify.diagnosis.blame.requirement_culprits`, with the
tightened bound (a bound, never a coefficient) as a repair Z3 checked.  A
requirement refuted only by its end-to-end deadline is not diagnosed here:
its deadline is (:mod:`rclverify.diagnosis.deadline`)."""
from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any

from rclverify.diagnosis import blame, recheck
from rclverify.diagnosis.liveness import liveness_culprits
from rclverify.diagnosis.progress_repair import progress_repairs
from rclverify.diagnosis.repairs import _record as _repair
from fractions import Fraction
from rclverify.lang.printer import expr_to_rcl
from rclverify.calculus.compose import conjuncts
from rclverify.diagnosis.shapes import CulpritRow, ProducerCulprits, ReportRows, Strengthening
from rclverify.records.report_schema import RequirementJson, SideConditionJson
from rclverify.records.stage_records import CexRow, Culprit, DiagnosisEntry, Repair

#: ``guarantee_source(report, node, k)``: a guarantee's (text, source) (diagnosis/build.py).
GuaranteeSource = Callable[[ReportRows, str, int], tuple[str, str]]

#: The repair kind of each way a culprit was found (:func:`blame.requirement_culprits`).
_KIND = {"bound": "tighten-bound", "threshold": "move-threshold", "conclusion": "strengthen-guarantee"}


def requirement_record(ws: Any, report: ReportRows, q: RequirementJson, cache: Any,
                       guarantee_source: GuaranteeSource) -> DiagnosisEntry:
    """The diagnosis record (:mod:`rclverify.diagnosis.build`) of the refuted
    requirement ``q`` (a report row): the guarantees Z3 showed a
    strengthening of proves it (:func:`blame.requirement_culprits`), each
    with that strengthening as a repair; the counterexample shown for the
    nodes involved only (the nodes the statement mentions, the culprits'
    nodes and the nodes between them).  ``cache`` keeps the culprits
    (``repair_cache.RepairCache``); ``guarantee_source(report, node, k)`` gives a
    guarantee's (text, source)."""
    check = q.get("check") or {}
    cone = [str(n) for n in check.get("cone") or []]
    run = next((t for t in check.get("traces") or [] if t.get("status") == "failed"), None)
    if run is not None:  # a recorded run refutes it: that run's step and values, not Z3's (empty) counterexample
        return _run_record(q, check, run)
    if check.get("temporal"):
        rec = _temporal_record(q, check, lambda: cache.get(
            ["progress-repair", q["id"], check.get("formal"), cone],
            lambda: progress_repairs(ws, q, check["temporal"])) or [])
        if rec["culprits"]:
            return rec
        # a run that meets every contract: the guarantee an edit by one value fixes (an off-by-one)
        slips = cache.get(["temporal-culprits", q["id"], check.get("formal"), cone],
                          lambda: _slips(ws, report, q, guarantee_source)) or []
        return _with_slips(rec, q, check, slips) if slips else rec

    causes = _causes(ws, report, q, cone, cache)
    if causes:  # refuted only because a side condition fails: that problem's row, its culprit
        return _consequence_record(report, q, check, causes, guarantee_source)

    found: list[CulpritRow] = cache.get(["requirement", q["id"], check.get("formal"), cone],
                                        lambda: _culprit_rows(ws, report, q, cone, guarantee_source)) or []
    cul: list[Culprit] = [{"what": f"guarantee {f['guarantee']} of {f['node']}: `{f['text']}`", "source": f["source"],
            "text": f["text"]} for f in found]
    mentioned = {str(r["node"]) for r in check.get("counterexample") or []
                 if re.search(rf"(?<![\w.]){re.escape(str(r['node']))}\.(in|out)\.", str(check.get("formal") or ""))}
    blamed = {str(f["node"]) for f in found}
    involved = mentioned | blamed | _between(report, blamed, mentioned)
    table: list[CexRow] = [{"node": r["node"], "variable": v, "value": x, "table": None}
                           for r in check.get("counterexample") or [] if not involved or str(r["node"]) in involved
             for v, x in r["values"].items()]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    sentence = _refuted(q, check, found[0] if found else None, cex)
    through = _passes_through(ws, report, q, cone)
    if through:  # the counterexample runs through another node's refuted side condition: say so
        sentence += " Its counterexample passes through " + "; ".join(
            f"the failed side condition {sc['id']} ({sc['node']}'s assumption `{sc['conjunct']}`, {sc['source']}, "
            "is false there)" for sc in through) + "."
    return {"id": str(q["id"]), "kind": "requirement", "node": found[0]["node"] if found else "", "status": "failed",
            "sentence": sentence, "culprits": cul, "counterexample": table,
            "repairs": [f["repair"] for f in found], "guarantee": None, "related": [],
            "passes_through": [str(sc["id"]) for sc in through]}


def _culprit_rows(ws: Any, report: ReportRows, q: RequirementJson, cone: list[str],
                  guarantee_source: GuaranteeSource) -> list[CulpritRow]:
    """One row per guarantee whose strengthening Z3 showed proves ``q``
    (:func:`blame.requirement_culprits`), with that strengthening as a repair."""
    rows: list[CulpritRow] = []
    for f in blame.requirement_culprits(ws, str(q["id"]), cone):
        source = recheck.source_text(ws, f["edit"].file)
        text, src = guarantee_source(report, f["node"], f["guarantee"])
        checks = [{"check": str(q["id"]), "status": "proved (Z3: unsat)"},
                  {"check": f"{f['node']} implementable",
                   "status": "yes: every input its assumption allows has an answer (Z3: proved)"
                   if f.get("implementable") == "proved" else "not decided (Z3 could not say in its budget)"}]
        not_shown = (f"that {f['node']} can meet the stronger guarantee: its evidence must establish it"
                     if f["how"] != "threshold" else
                     f"that the threshold {q['id']} states is the right one for the robot, and that {f['node']} "
                     "meets it: its evidence must establish it")
        rows.append({"node": f["node"], "guarantee": f["guarantee"], "how": f["how"], "old": f["old"],
                     "new": f["new"], "text": text, "source": src,
                     "repair": _repair(_KIND[f["how"]], _summary(f, q, src), f["edit"], source, checks,
                                       blame.cost(ws, report, f["node"], f["edit"]),
                                       proves=f"{q['id']} follows from the edited contracts, from consistent "
                                              "premises",
                                       not_shown=not_shown)})
    return rows


def _summary(f: Strengthening, q: RequirementJson, src: str) -> str:
    """The repair's one-paragraph summary for culprit ``f`` (``src`` its guarantee's location)."""
    what = f"guarantee {f['guarantee']} of {f['node']}"
    if f["how"] == "bound":
        return (f"Tighten the bound of {what} ({src}): {f['old']} becomes {f['new']}; Z3 proves "
                f"{q['id']} from consistent premises. {f['node']}'s evidence must then establish it.")
    if f["how"] == "threshold":
        return (f"Make the threshold of {what} ({src}) {'include' if f['inclusive'] else 'exclude'} "
                f"{f['threshold']} itself: `{f['old']}` becomes `{f['new']}`, as {q['id']} states it "
                "(an off-by-one at the threshold); Z3 "
                f"proves {q['id']} from consistent premises. {f['node']}'s implementation and evidence "
                "must then decide the threshold value itself the same way.")
    return (f"Strengthen {what} ({src}) by `{f['new']}`; Z3 proves {q['id']} from consistent premises. "
            f"{f['node']}'s evidence must then establish it.")


def _refuted(q: RequirementJson, check: Mapping[str, object], f: CulpritRow | None, cex: str) -> str:
    """The record's sentence: why ``q`` is refuted, naming the first culprit
    ``f`` (``None``: no single strengthening proves it) and the counterexample."""
    if f is not None:
        how = (f"its bound {f['old']} lets the counterexample through; with {f['new']} Z3 proves {q['id']}"
               if f["how"] == "bound" else
               f"its threshold `{f['old']}` has the other strictness than {q['id']}'s (an off-by-one at the "
               f"threshold); with `{f['new']}` Z3 proves {q['id']}" if f["how"] == "threshold" else
               f"strengthened by `{f['new']}` it lets Z3 prove {q['id']}")
        return (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted because of "
                f"guarantee {f['guarantee']} of {f['node']} ({f['source']}) `{f['text']}`: {how}"
                + (f". Z3's counterexample: {cex}" if cex else "") + ".")
    return (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted: the guarantees "
            "of its cone allow a counterexample, and no single strengthening Z3 tried proves it"
            + (f". Z3's counterexample: {cex}" if cex else "") + ".")


def _causes(ws: Any, report: ReportRows, q: RequirementJson, cone: list[str],
            cache: Any) -> list[tuple[SideConditionJson, str, int]]:
    """``[(side condition row, producer, guarantee index)]``: the failed side
    conditions of ``q``'s cone whose discharge alone proves ``q`` -- each
    producer guarantee that discharges it when strengthened by the
    consumer's conjunct (:func:`blame.side_condition_culprits`, the same
    cache entry as the side condition's own record), with which Z3 then
    proves ``q`` from consistent premises (:func:`blame.proved_with`).  The
    requirement is then a consequence of that problem, not a problem of its
    own (docs/diagnosis.md, "One row per cause")."""
    out: list[tuple[SideConditionJson, str, int]] = []
    check = q.get("check") or {}
    for sc in report.get("side_conditions") or ():
        if sc.get("status") != "failed" or str(sc.get("node")) not in cone:
            continue
        def producers(sc: SideConditionJson = sc) -> ProducerCulprits:  # as diagnosis/build.py keeps them
            found, undecided = blame.side_condition_culprits(ws, sc)
            return {"culprits": [list(x) for x in found], "undecided": undecided}
        shown: ProducerCulprits | None = cache.get(["sc-culprits", sc["id"], sc["conjunct"]], producers)
        for p, k in (shown.get("culprits") or []) if shown else ():
            def proves(p: str = str(p), k: int = int(k), sc: SideConditionJson = sc) -> bool:
                edit = blame.fixed_side_condition(ws, sc, p, k)
                return edit is not None and blame.proved_with(ws, str(q["id"]), edit)
            if cache.get(["consequence", q["id"], check.get("formal"), cone, sc["id"], sc["conjunct"], p, k], proves):
                out.append((sc, str(p), int(k)))
    return out


def _cex_value(text: Any) -> Any:
    """A counterexample's value text as a value of :mod:`rclverify.semantics.values`
    (a number or a boolean); ``None`` for anything else."""
    t = str(text).strip()
    if t in ("true", "false", "TRUE", "FALSE"):
        return t.lower() == "true"
    try:
        return Fraction(t)
    except (ValueError, ZeroDivisionError):
        return None


def _passes_through(ws: Any, report: ReportRows, q: RequirementJson,
                    cone: list[str]) -> list[SideConditionJson]:
    """The failed side conditions of ``q``'s cone whose conjunct is false on
    the consumer's values in ``q``'s counterexample (decided by the
    monitors' evaluator, :func:`rclverify.semantics.decide.decide`): the
    counterexample passes through them.  A value that does not read, or a
    conjunct the evaluator cannot decide, counts as not passing."""
    from rclverify.semantics.decide import decide  # deferred: start-up (loads rclverify.semantics.concrete, rclverify.semantics.decide and more only when called)
    rows = {str(r["node"]): r.get("values") or {} for r in (q.get("check") or {}).get("counterexample") or []}
    out = []
    for sc in report.get("side_conditions") or ():
        node = str(sc.get("node"))
        if sc.get("status") != "failed" or node not in cone or node not in rows:
            continue
        values = {k: _cex_value(v) for k, v in rows[node].items()}
        try:
            cn = ws.checked.nodes[node]
            conj = next((c for a in cn.node.assumes for c in conjuncts(a.formula)
                         if expr_to_rcl(c) == sc["conjunct"]), None)
            if conj is not None and None not in values.values() and decide(conj, ws.checked, cn, values)[0] is False:
                out.append(sc)
        except Exception:  # noqa: BLE001 - a value or conjunct the evaluator cannot take: not shown to pass
            continue
    return out


def _consequence_record(report: ReportRows, q: RequirementJson, check: Mapping[str, Any],
                        causes: list[tuple[SideConditionJson, str, int]],
                        guarantee_source: GuaranteeSource) -> DiagnosisEntry:
    """The diagnosis record of a requirement refuted only because of the
    failed side conditions ``causes`` (:func:`_causes`): its culprits are
    theirs (the consumer's assumption and the producer's guarantee), its
    ``consequence_of`` their ids; no repair of its own (the side condition's
    repairs are the row's)."""
    cul: list[Culprit] = []
    said: list[str] = []
    for sc, p, k in causes:
        text, src = guarantee_source(report, p, k)
        both: list[Culprit] = [{"what": f"assumption of {sc['node']}: `{sc['conjunct']}`", "source": sc["source"],
                                "text": sc["conjunct"]},
                               {"what": f"guarantee {k} of {p}: `{text}`", "source": src, "text": text}]
        for c in both:
            if c not in cul:
                cul.append(c)
        said.append(f"side condition {sc['id']} ({sc['node']} assumes `{sc['conjunct']}`, {sc['source']}) fails "
                    f"through guarantee {k} of {p} ({src}) `{text}`")
    table: list[CexRow] = [{"node": r["node"], "variable": v, "value": x, "table": None}
                           for r in check.get("counterexample") or [] for v, x in r["values"].items()]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    ids = list(dict.fromkeys(str(sc["id"]) for sc, _, _ in causes))
    sentence = (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted only because "
                + "; and ".join(said) + f": with that side condition discharged Z3 proves {q['id']}, so its "
                "counterexample passes through the failed side condition"
                + (f". Z3's counterexample: {cex}" if cex else "") + ".")
    return {"id": str(q["id"]), "kind": "requirement", "node": causes[0][1], "status": "failed",
            "sentence": sentence, "culprits": cul, "counterexample": table, "repairs": [], "guarantee": None,
            "related": [], "consequence_of": ids}


def _slips(ws: Any, report: ReportRows, q: RequirementJson,
           guarantee_source: GuaranteeSource) -> list[CulpritRow]:
    """The guarantees :func:`blame.temporal_culprits` names for the refuted
    temporal requirement ``q``, each ``{"node", "guarantee", "how", "old",
    "new", "text", "source", "repair"}`` (its edit as a repair Z3 checked)."""
    check = q.get("check") or {}
    rows: list[CulpritRow] = []
    for f in blame.temporal_culprits(ws, str(q["id"]), [str(n) for n in check.get("cone") or []]):
        text, src = guarantee_source(report, f["node"], f["guarantee"])
        what = f"guarantee {f['guarantee']} of {f['node']}"
        kind = "an index offset" if f["how"] == "offset" else "a threshold's strictness"
        summary = (f"Change {kind} of {what} ({src}) by one: `{f['old']}` becomes `{f['new']}`; Z3's temporal check "
                   f"proves {q['id']}. {f['node']}'s implementation and evidence must then do the same.")
        rows.append({"node": f["node"], "guarantee": f["guarantee"], "how": f["how"], "old": f["old"],
                     "new": f["new"], "text": text, "source": src,
                     "repair": _repair("move-threshold" if f["how"] == "threshold" else "tighten-bound", summary,
                                       f["edit"], recheck.source_text(ws, f["edit"].file),
                                       [{"check": str(q["id"]), "status": "proved (temporal check)"},
                                        {"check": f"{f['node']} implementable",
                                         "status": "yes (Z3: proved)" if f.get("implementable") == "proved"
                                         else "not decided (Z3 could not say in its budget)"}],
                                       blame.cost(ws, report, f["node"], f["edit"]),
                                       proves=f"{q['id']} holds on every run of the edited contracts",
                                       not_shown=f"that the edited value is the one {f['node']} must compute: its "
                                                 "evidence must establish it")})
    return rows


def _with_slips(rec: DiagnosisEntry, q: RequirementJson, check: Mapping[str, object],
                slips: list[CulpritRow]) -> DiagnosisEntry:
    """``rec`` (a temporal record without a culprit) naming the guarantees of ``slips`` (:func:`_slips`)."""
    f = slips[0]
    marker = next((m for m in (" The state it repeats: ", " Its last state: ") if m in rec["sentence"]), None)
    head = (rec["sentence"].split(marker)[0] if marker else rec["sentence"]).split(" that meets every contract")[0]
    state = rec["sentence"].split(marker, 1)[1].split(". No guarantee")[0] if marker else ""
    sentence = (f"{head}, because of guarantee {f['guarantee']} of {f['node']} ({f['source']}) `{f['text']}`: "
                f"with `{f['old']}` as `{f['new']}` (off by one) Z3's temporal check proves {q['id']}"
                + (f". The state: {state}" if state else "") + ".")
    return {**rec, "node": f["node"], "sentence": sentence,
            "culprits": [{"what": f"guarantee {x['guarantee']} of {x['node']}: `{x['text']}`", "source": x["source"],
                          "text": x["text"]} for x in slips],
            "repairs": [x["repair"] for x in slips]}


def _between(report: ReportRows, sources: set[str], sinks: set[str]) -> set[str]:
    """The nodes on a path of the system's connections from a node of
    ``sources`` to a node of ``sinks`` (both excluded)."""
    down: dict[str, set[str]] = {}
    for c in report.get("system", {}).get("connections", []):
        down.setdefault(str(c["from_node"]), set()).add(str(c["to_node"]))
    up: dict[str, set[str]] = {}
    for a, bs in down.items():
        for b in bs:
            up.setdefault(b, set()).add(a)

    def reach(start: set[str], edges: Mapping[str, set[str]]) -> set[str]:
        seen, todo = set(start), list(start)
        while todo:
            for m in edges.get(todo.pop(), ()):
                if m not in seen:
                    seen.add(m)
                    todo.append(m)
        return seen
    return (reach(sources, down) & reach(sinks, up)) - sources - sinks


def _run_record(q: RequirementJson, check: Mapping[str, Any], row: Mapping[str, Any]) -> DiagnosisEntry:
    """The diagnosis of a requirement a recorded run refutes
    (backends/monitors/temporal_evidence.py: a trace row ``failed``): the
    run, the step of the composed system at which it was refuted
    (docs/semantics.md, "Steps") with its message and time, and the values
    the operand read there, as the counterexample.  What Z3 said of the
    contracts is kept beside it: a run that breaks what the contracts prove
    breaks one of its premises (a node's guarantee or declaration, an
    assumption of the environment), which that run's evidence of the
    nodes names."""
    v = row.get("verdict") or {}
    witness = [w for w in v.get("witness") or [] if isinstance(w, Mapping)]
    table: list[CexRow] = []
    for w in witness:
        for name, value in (w.get("values") or {}).items():
            node, _, var = str(name).partition(".")
            table.append({"node": node, "variable": var, "value": str(value), "table": None})
    at = (f"step {v['step']} of the run ({v.get('where')}, t = {v.get('time')} s)" if v.get("step") is not None
          else "its end")
    seen = "; ".join(f"{w.get('operand')} is {'true' if w.get('holds') else 'false' if w.get('holds') is False else 'undecided'}"
                     f" at step {w.get('step')} ({w.get('where')})"
                     + (" with " + ", ".join(f"{k} = {x}" for k, x in (w.get("values") or {}).items())
                        if w.get("values") else "") for w in witness)
    proof = (check.get("temporal") or {}).get("status") or q.get("verdict")
    z3 = (" Over the composed contracts it is proved: the run breaks a premise of that proof (a node's guarantee "
          "or declaration, or an assumption of the environment), which the run's evidence of each node names."
          if proof in ("proved", "met") else f" Over the composed contracts: {proof}." if proof else "")
    sentence = (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted by the recorded "
                f"run {row.get('trace')} at {at}: {v.get('reason', '')}"
                + (f". {seen[0].upper()}{seen[1:]}" if seen else "") + " (a step of the run is a step of the "
                f"composed system, as in the proof: docs/semantics.md, \"Steps\").{z3}")
    return {"id": str(q["id"]), "kind": "requirement", "node": "", "status": "failed", "sentence": sentence,
            "culprits": [], "counterexample": table, "repairs": [], "guarantee": None, "related": []}


def _temporal_record(q: RequirementJson, check: Mapping[str, Any],
                     repairs: Callable[[], list[Repair]]) -> DiagnosisEntry:
    """The diagnosis of a refuted temporal requirement: its counterexample
    run (docs/requirements.md, "Temporal requirements"), the state it loops
    through shown node by node.  A lasso that rests on a node that never
    answers (or on a loop stuck on values from before the run) names that
    node, through :func:`.liveness.liveness_culprits`; for a node that never
    answers, ``repairs()`` gives the progress declarations with which the
    requirement is proved (:mod:`.progress_repair`); otherwise no culprit
    is named: the run meets every contract, and no strengthening is searched
    for a temporal statement (docs/diagnosis.md: only what Z3 showed is
    named)."""
    t = check["temporal"]
    trace = t.get("shown") or t.get("trace") or []  # cut to what matters (report/cex_cone.py)
    loop = t.get("loop")
    shown = trace[loop] if loop is not None and 0 <= loop < len(trace) else (trace[-1] if trace else {"nodes": []})
    table: list[CexRow] = [{"node": r["node"], "variable": v, "value": x, "table": None}
                           for r in shown.get("nodes", []) for v, x in r["values"].items()]
    run = (f"a run of {len(trace)} states whose last returns to step {loop} and repeats forever"
           if loop is not None and trace else f"a run of {len(trace)} states" if trace else "a run")
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    # a state is named only when the check kept one (never "The state it repeats: .")
    said = (f"The state it repeats: {cex}" if loop is not None else f"Its last state: {cex}") if cex else ""
    node, culprits, missing = liveness_culprits(t)
    if missing:
        sentence = (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted by {run} in "
                    f"which {missing}." + (f" {said}" if said else "") + f" ({t.get('method')}; {t.get('detail')}).")
    else:
        sentence = (f"Requirement {q['id']} (`{check.get('formal')}`, {check.get('source')}) is refuted by {run} that "
                    f"meets every contract of its cone ({t.get('method')}; {t.get('detail')}). "
                    + (f"{said}. " if said else "") + "No guarantee of the cone prevents it: "
                    "a guarantee that forces progress, or an assuming: that excludes the run, is needed.")
    fixes = repairs() if t.get("missing_progress") else []
    return {"id": str(q["id"]), "kind": "requirement", "node": node, "status": "failed", "sentence": sentence,
            "culprits": culprits, "counterexample": table, "repairs": fixes, "guarantee": None, "related": []}
