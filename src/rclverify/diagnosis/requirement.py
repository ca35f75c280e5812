"""The diagnosis record of a refuted requirement (docs/diagnosis.md, "Who
is named"): the guarantee whose bound lets Z3's counterexample through,
found by :func:`rclverify.diagnosis.blame.requirement_culprits`, with the
tightened bound (a bound, never a coefficient) as a repair Z3 checked.  A
requirement refuted only by its end-to-end deadline is not diagnosed here:
its deadline is (:mod:`rclverify.diagnosis.deadline`)."""
from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any, cast

from rclverify.diagnosis import blame, recheck
from rclverify.diagnosis.liveness import liveness_culprits
from rclverify.diagnosis.progress_repair import progress_repairs
from rclverify.diagnosis.repairs import _record as _repair
from fractions import Fraction
from rclverify.lang.printer import expr_to_rcl
from rclverify.calculus.compose import conjuncts
from rclverify.diagnosis.shapes import (CulpritRow, ProducerCulprits, ReportRows, Strengthening, culprit_rows,
                                        culprit_rows_json)
from rclverify.calculus.shapes import Gaps
from rclverify.records.requirement_check import RequirementCheckRow, TraceCheckRow, TraceVerdictRow
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.diagnosis.record import diagnosis_record, with_culprits
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.stage_records import CexRow, Culprit, Repair

#: ``guarantee_source(report, node, k)``: a guarantee's (text, source) (diagnosis/build.py).
GuaranteeSource = Callable[[ReportRows, str, int], tuple[str, str]]

#: The repair kind of each way a culprit was found (:func:`blame.requirement_culprits`).
_KIND = {"bound": "tighten-bound", "threshold": "move-threshold", "conclusion": "strengthen-guarantee"}


def requirement_record(ws: Any, report: ReportRows, q: RequirementRow, cache: Any,
                       guarantee_source: GuaranteeSource) -> DiagnosisRow:
    """The diagnosis record (:mod:`rclverify.diagnosis.build`) of the refuted
    requirement ``q`` (the report's record): the guarantees Z3 showed a
    strengthening of proves it (:func:`blame.requirement_culprits`), each
    with that strengthening as a repair; the counterexample shown for the
    nodes involved only (the nodes the statement mentions, the culprits'
    nodes and the nodes between them).  ``cache`` keeps the culprits
    (``repair_cache.RepairCache``); ``guarantee_source(report, node, k)`` gives a
    guarantee's (text, source)."""
    check = RequirementCheckRow.of(q.check)
    cone = check.cone
    run = next((t for t in check.traces if t.status == "failed"), None)
    if run is not None:  # a recorded run refutes it: that run's step and values, not Z3's (empty) counterexample
        return _run_record(q, check, run)
    if check.temporal:
        temporal = check.temporal
        rec = _temporal_record(q.id, check, lambda: cache.get(
            ["progress-repair", q.id, check.formal, cone],
            lambda: progress_repairs(ws, q, cast("Gaps", temporal))) or [])
        if rec.culprits:
            return rec
        # a run that meets every contract: the guarantee an edit by one value fixes (an off-by-one)
        slips = culprit_rows(cache.get(["temporal-culprits", q.id, check.formal, cone],
                                       lambda: culprit_rows_json(_slips(ws, report, q, guarantee_source))))
        return _with_slips(rec, q, check, slips) if slips else rec

    causes = _causes(ws, report, q, cone, cache)
    if causes:  # refuted only because a side condition fails: that problem's row, its culprit
        return _consequence_record(report, q, check, causes, guarantee_source)

    found = culprit_rows(cache.get(["requirement", q.id, check.formal, cone],
                                   lambda: culprit_rows_json(_culprit_rows(ws, report, q, cone, guarantee_source))))
    cul: list[Culprit] = [{"what": f"guarantee {f.guarantee} of {f.node}: `{f.text}`", "source": f.source,
            "text": f.text} for f in found]
    mentioned = {r.node for r in check.counterexample
                 if re.search(rf"(?<![\w.]){re.escape(r.node)}\.(in|out)\.", check.formal or "")}
    blamed = {f.node for f in found}
    involved = mentioned | blamed | _between(report, blamed, mentioned)
    table: list[CexRow] = [{"node": r.node, "variable": v, "value": x, "table": None}
                           for r in check.counterexample if not involved or r.node in involved
             for v, x in r.values.items()]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    sentence = _refuted(q, check, found[0] if found else None, cex)
    through = _passes_through(ws, report, check, cone)
    if through:  # the counterexample runs through another node's refuted side condition: say so
        sentence += " Its counterexample passes through " + "; ".join(
            f"the failed side condition {sc.id} ({sc.node}'s assumption `{sc.conjunct}`, {sc.source}, "
            "is false there)" for sc in through) + "."
    return diagnosis_record(q.id, "requirement", found[0].node if found else "", "failed", sentence, culprits=cul,
                            counterexample=table, repairs=[f.repair_record() for f in found],
                            passes_through=[sc.id for sc in through])


def _culprit_rows(ws: Any, report: ReportRows, q: RequirementRow, cone: list[str],
                  guarantee_source: GuaranteeSource) -> list[CulpritRow]:
    """One row per guarantee whose strengthening Z3 showed proves ``q``
    (:func:`blame.requirement_culprits`), with that strengthening as a repair."""
    rows: list[CulpritRow] = []
    for f in blame.requirement_culprits(ws, q.id, cone):
        source = recheck.source_text(ws, f.edit.file)
        text, src = guarantee_source(report, f.node, f.guarantee)
        checks = [{"check": q.id, "status": "proved (Z3: unsat)"},
                  {"check": f"{f.node} implementable",
                   "status": "yes: every input its assumption allows has an answer (Z3: proved)"
                   if f.implementable == "proved" else "not decided (Z3 could not say in its budget)"}]
        not_shown = (f"that {f.node} can meet the stronger guarantee: its evidence must establish it"
                     if f.how != "threshold" else
                     f"that the threshold {q.id} states is the right one for the robot, and that {f.node} "
                     "meets it: its evidence must establish it")
        rows.append(CulpritRow(f.node, f.guarantee, f.how, f.old, f.new, text, src,
                               dict(_repair(_KIND[f.how], _summary(f, q, src), f.edit, source, checks,
                                            blame.cost(ws, report, f.node, f.edit),
                                            proves=f"{q.id} follows from the edited contracts, from consistent "
                                                   "premises",
                                            not_shown=not_shown))))
    return rows


def _summary(f: Strengthening, q: RequirementRow, src: str) -> str:
    """The repair's one-paragraph summary for culprit ``f`` (``src`` its guarantee's location)."""
    what = f"guarantee {f.guarantee} of {f.node}"
    if f.how == "bound":
        return (f"Tighten the bound of {what} ({src}): {f.old} becomes {f.new}; Z3 proves "
                f"{q.id} from consistent premises. {f.node}'s evidence must then establish it.")
    if f.how == "threshold":
        return (f"Make the threshold of {what} ({src}) {'include' if f.inclusive else 'exclude'} "
                f"{f.threshold} itself: `{f.old}` becomes `{f.new}`, as {q.id} states it "
                "(an off-by-one at the threshold); Z3 "
                f"proves {q.id} from consistent premises. {f.node}'s implementation and evidence "
                "must then decide the threshold value itself the same way.")
    return (f"Strengthen {what} ({src}) by `{f.new}`; Z3 proves {q.id} from consistent premises. "
            f"{f.node}'s evidence must then establish it.")


def _refuted(q: RequirementRow, check: RequirementCheckRow, f: CulpritRow | None, cex: str) -> str:
    """The record's sentence: why ``q`` is refuted, naming the first culprit
    ``f`` (``None``: no single strengthening proves it) and the counterexample."""
    if f is not None:
        how = (f"its bound {f.old} lets the counterexample through; with {f.new} Z3 proves {q.id}"
               if f.how == "bound" else
               f"its threshold `{f.old}` has the other strictness than {q.id}'s (an off-by-one at the "
               f"threshold); with `{f.new}` Z3 proves {q.id}" if f.how == "threshold" else
               f"strengthened by `{f.new}` it lets Z3 prove {q.id}")
        return (f"Requirement {q.id} (`{check.formal}`, {check.source}) is refuted because of "
                f"guarantee {f.guarantee} of {f.node} ({f.source}) `{f.text}`: {how}"
                + (f". Z3's counterexample: {cex}" if cex else "") + ".")
    return (f"Requirement {q.id} (`{check.formal}`, {check.source}) is refuted: the guarantees "
            "of its cone allow a counterexample, and no single strengthening Z3 tried proves it"
            + (f". Z3's counterexample: {cex}" if cex else "") + ".")


def _causes(ws: Any, report: ReportRows, q: RequirementRow, cone: list[str],
            cache: Any) -> list[tuple[SideConditionRow, str, int]]:
    """``[(side condition row, producer, guarantee index)]``: the failed side
    conditions of ``q``'s cone whose discharge alone proves ``q`` -- each
    producer guarantee that discharges it when strengthened by the
    consumer's conjunct (:func:`blame.side_condition_culprits`, the same
    cache entry as the side condition's own record), with which Z3 then
    proves ``q`` from consistent premises (:func:`blame.proved_with`).  The
    requirement is then a consequence of that problem, not a problem of its
    own (docs/diagnosis.md, "One row per cause")."""
    out: list[tuple[SideConditionRow, str, int]] = []
    formal = RequirementCheckRow.of(q.check).formal
    for sc in report.side_conditions:
        if sc.status != "failed" or sc.node not in cone:
            continue
        def producers(sc: SideConditionRow = sc) -> ProducerCulprits:  # as diagnosis/build.py keeps them
            found, undecided = blame.side_condition_culprits(ws, sc)
            return {"culprits": [list(x) for x in found], "undecided": undecided}
        shown: ProducerCulprits | None = cache.get(["sc-culprits", sc.id, sc.conjunct], producers)
        for p, k in (shown.get("culprits") or []) if shown else ():
            def proves(p: str = str(p), k: int = int(k), sc: SideConditionRow = sc) -> bool:
                edit = blame.fixed_side_condition(ws, sc, p, k)
                return edit is not None and blame.proved_with(ws, q.id, edit)
            if cache.get(["consequence", q.id, formal, cone, sc.id, sc.conjunct, p, k], proves):
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


def _passes_through(ws: Any, report: ReportRows, check: RequirementCheckRow,
                    cone: list[str]) -> list[SideConditionRow]:
    """The failed side conditions of ``cone`` whose conjunct is false on
    the consumer's values in the counterexample of a requirement's ``check`` (decided by the
    monitors' evaluator, :func:`rclverify.semantics.decide.decide`): the
    counterexample passes through them.  A value that does not read, or a
    conjunct the evaluator cannot decide, counts as not passing."""
    from rclverify.semantics.decide import decide  # deferred: start-up (loads rclverify.semantics.concrete, rclverify.semantics.decide and more only when called)
    rows = {r.node: r.values for r in check.counterexample}
    out = []
    for sc in report.side_conditions:
        node = sc.node
        if sc.status != "failed" or node not in cone or node not in rows:
            continue
        values = {k: _cex_value(v) for k, v in rows[node].items()}
        try:
            cn = ws.checked.nodes[node]
            conj = next((c for a in cn.node.assumes for c in conjuncts(a.formula)
                         if expr_to_rcl(c) == sc.conjunct), None)
            if conj is not None and None not in values.values() and decide(conj, ws.checked, cn, values)[0] is False:
                out.append(sc)
        except Exception:  # noqa: BLE001 - a value or conjunct the evaluator cannot take: not shown to pass
            continue
    return out


def _consequence_record(report: ReportRows, q: RequirementRow, check: RequirementCheckRow,
                        causes: list[tuple[SideConditionRow, str, int]],
                        guarantee_source: GuaranteeSource) -> DiagnosisRow:
    """The diagnosis record of a requirement refuted only because of the
    failed side conditions ``causes`` (:func:`_causes`): its culprits are
    theirs (the consumer's assumption and the producer's guarantee), its
    ``consequence_of`` their ids; no repair of its own (the side condition's
    repairs are the row's)."""
    cul: list[Culprit] = []
    said: list[str] = []
    for sc, p, k in causes:
        text, src = guarantee_source(report, p, k)
        both: list[Culprit] = [{"what": f"assumption of {sc.node}: `{sc.conjunct}`", "source": sc.source,
                                "text": sc.conjunct},
                               {"what": f"guarantee {k} of {p}: `{text}`", "source": src, "text": text}]
        for c in both:
            if c not in cul:
                cul.append(c)
        said.append(f"side condition {sc.id} ({sc.node} assumes `{sc.conjunct}`, {sc.source}) fails "
                    f"through guarantee {k} of {p} ({src}) `{text}`")
    table: list[CexRow] = [{"node": r.node, "variable": v, "value": x, "table": None}
                           for r in check.counterexample for v, x in r.values.items()]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    ids = list(dict.fromkeys(sc.id for sc, _, _ in causes))
    sentence = (f"Requirement {q.id} (`{check.formal}`, {check.source}) is refuted only because "
                + "; and ".join(said) + f": with that side condition discharged Z3 proves {q.id}, so its "
                "counterexample passes through the failed side condition"
                + (f". Z3's counterexample: {cex}" if cex else "") + ".")
    return diagnosis_record(q.id, "requirement", causes[0][1], "failed", sentence, culprits=cul,
                            counterexample=table, consequence_of=ids)


def _slips(ws: Any, report: ReportRows, q: RequirementRow,
           guarantee_source: GuaranteeSource) -> list[CulpritRow]:
    """The guarantees :func:`blame.temporal_culprits` names for the refuted
    temporal requirement ``q``, each a :class:`~rclverify.diagnosis.shapes.CulpritRow`
    (its edit as a repair Z3 checked)."""
    rows: list[CulpritRow] = []
    for f in blame.temporal_culprits(ws, q.id, RequirementCheckRow.of(q.check).cone):
        text, src = guarantee_source(report, f.node, f.guarantee)
        what = f"guarantee {f.guarantee} of {f.node}"
        kind = "an index offset" if f.how == "offset" else "a threshold's strictness"
        summary = (f"Change {kind} of {what} ({src}) by one: `{f.old}` becomes `{f.new}`; Z3's temporal check "
                   f"proves {q.id}. {f.node}'s implementation and evidence must then do the same.")
        rows.append(CulpritRow(f.node, f.guarantee, f.how, f.old, f.new, text, src,
                               dict(_repair("move-threshold" if f.how == "threshold" else "tighten-bound", summary,
                                            f.edit, recheck.source_text(ws, f.edit.file),
                                            [{"check": q.id, "status": "proved (temporal check)"},
                                             {"check": f"{f.node} implementable",
                                              "status": "yes (Z3: proved)" if f.implementable == "proved"
                                              else "not decided (Z3 could not say in its budget)"}],
                                            blame.cost(ws, report, f.node, f.edit),
                                            proves=f"{q.id} holds on every run of the edited contracts",
                                            not_shown=f"that the edited value is the one {f.node} must compute: "
                                                      "its evidence must establish it"))))
    return rows


def _with_slips(rec: DiagnosisRow, q: RequirementRow, check: RequirementCheckRow,
                slips: list[CulpritRow]) -> DiagnosisRow:
    """``rec`` (a temporal record without a culprit) naming the guarantees of ``slips`` (:func:`_slips`)."""
    f = slips[0]
    marker = next((m for m in (" The state it repeats: ", " Its last state: ") if m in rec.sentence), None)
    head = (rec.sentence.split(marker)[0] if marker else rec.sentence).split(" that meets every contract")[0]
    state = rec.sentence.split(marker, 1)[1].split(". No guarantee")[0] if marker else ""
    sentence = (f"{head}, because of guarantee {f.guarantee} of {f.node} ({f.source}) `{f.text}`: "
                f"with `{f.old}` as `{f.new}` (off by one) Z3's temporal check proves {q.id}"
                + (f". The state: {state}" if state else "") + ".")
    return with_culprits(rec, f.node, sentence,
                         [{"what": f"guarantee {x.guarantee} of {x.node}: `{x.text}`", "source": x.source,
                           "text": x.text} for x in slips],
                         [x.repair_record() for x in slips])


def _between(report: ReportRows, sources: set[str], sinks: set[str]) -> set[str]:
    """The nodes on a path of the system's connections from a node of
    ``sources`` to a node of ``sinks`` (both excluded)."""
    down: dict[str, set[str]] = {}
    for c in report.system.connections:
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


def _run_record(q: RequirementRow, check: RequirementCheckRow, row: TraceCheckRow) -> DiagnosisRow:
    """The diagnosis of a requirement a recorded run refutes
    (backends/monitors/temporal_evidence.py: a trace row ``failed``): the
    run, the step of the composed system at which it was refuted
    (docs/semantics.md, "Steps") with its message and time, and the values
    the operand read there, as the counterexample.  What Z3 said of the
    contracts is kept beside it: a run that breaks what the contracts prove
    breaks one of its premises (a node's guarantee or declaration, an
    assumption of the environment), which that run's evidence of the
    nodes names."""
    v = row.verdict or TraceVerdictRow()
    witness = v.witness or []
    table: list[CexRow] = []
    for w in witness:
        for name, value in (w.values or {}).items():
            node, _, var = str(name).partition(".")
            table.append({"node": node, "variable": var, "value": str(value), "table": None})
    at = (f"step {v.step} of the run ({v.where}, t = {v.time} s)" if v.step is not None
          else "its end")
    seen = "; ".join(f"{w.operand} is {'true' if w.holds else 'false' if w.holds is False else 'undecided'}"
                     f" at step {w.step} ({w.where})"
                     + (" with " + ", ".join(f"{k} = {x}" for k, x in w.values.items())
                        if w.values else "") for w in witness)
    proof = (check.temporal or {}).get("status") or q.verdict
    z3 = (" Over the composed contracts it is proved: the run breaks a premise of that proof (a node's guarantee "
          "or declaration, or an assumption of the environment), which the run's evidence of each node names."
          if proof in ("proved", "met") else f" Over the composed contracts: {proof}." if proof else "")
    sentence = (f"Requirement {q.id} (`{check.formal}`, {check.source}) is refuted by the recorded "
                f"run {row.trace} at {at}: {v.reason}"
                + (f". {seen[0].upper()}{seen[1:]}" if seen else "") + " (a step of the run is a step of the "
                f"composed system, as in the proof: docs/semantics.md, \"Steps\").{z3}")
    return diagnosis_record(q.id, "requirement", "", "failed", sentence, counterexample=table)


def _temporal_record(req_id: str, check: RequirementCheckRow, repairs: Callable[[], list[Repair]]) -> DiagnosisRow:
    """The diagnosis of the refuted temporal requirement ``req_id`` from its
    ``check`` record: its counterexample
    run (docs/requirements.md, "Temporal requirements"), the state it loops
    through shown node by node.  A lasso that rests on a node that never
    answers (or on a loop stuck on values from before the run) names that
    node, through :func:`.liveness.liveness_culprits`; for a node that never
    answers, ``repairs()`` gives the progress declarations with which the
    requirement is proved (:mod:`.progress_repair`); otherwise no culprit
    is named: the run meets every contract, and no strengthening is searched
    for a temporal statement (docs/diagnosis.md: only what Z3 showed is
    named)."""
    t = check.temporal or {}
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
    node, culprits, missing = liveness_culprits(cast("Gaps", t))
    if missing:
        sentence = (f"Requirement {req_id} (`{check.formal}`, {check.source}) is refuted by {run} in "
                    f"which {missing}." + (f" {said}" if said else "") + f" ({t.get('method')}; {t.get('detail')}).")
    else:
        sentence = (f"Requirement {req_id} (`{check.formal}`, {check.source}) is refuted by {run} that "
                    f"meets every contract of its cone ({t.get('method')}; {t.get('detail')}). "
                    + (f"{said}. " if said else "") + "No guarantee of the cone prevents it: "
                    "a guarantee that forces progress, or an assuming: that excludes the run, is needed.")
    fixes = repairs() if t.get("missing_progress") else []
    return diagnosis_record(req_id, "requirement", node, "failed", sentence, culprits=culprits, counterexample=table,
                            repairs=fixes)
