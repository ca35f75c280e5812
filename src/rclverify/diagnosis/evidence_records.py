"""The diagnosis record of a failed or erroneous piece of evidence
(:func:`evidence_record`): the guarantee it refutes, named by source
location, its counterexample, and the repairs of its backend (a Hoare
proof's constant or token, a monitor's or property test's code line).
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import msgspec

from rclverify.diagnosis.code_repair_check import checked_repairs, repaired_line
from rclverify.diagnosis.constants import hoare_repair
from rclverify.diagnosis.hoare_tokens import hoare_token_repairs
from rclverify.diagnosis.monitor_repair import MonitorRepairs, report_repairs
from rclverify.diagnosis.record import diagnosis_record, guarantee_source
from rclverify.diagnosis.repair_cache import RepairCache
from rclverify.diagnosis.shapes import ReportRows
from rclverify.diagnosis.table import counterexample_table
from rclverify.records.evidence_rows import EvidenceRow
from rclverify.records.monitored_run import MonitoredRun
from rclverify.records.obligations import ObligationRow
from rclverify.records.problem_rows import DiagnosisRow
from rclverify.records.stage_records import Culprit, Repair

if TYPE_CHECKING:  # a type only: decoded where a failed monitored run is diagnosed (_monitors_payload)
    from rclverify.backends.monitors.payload import MonitorsPayload

_META_KEYS = {"conjunct", "facts", "guarantee", "reason", "replay", "source", "cause", "boundary"}


def _computed_line(obligations: Sequence[ObligationRow], evidence: Sequence[EvidenceRow], node: str, k: object,
                   file: str) -> str:
    """``file:line`` a failed property test of guarantee ``k`` of ``node``
    (among the report's ``obligations`` and ``evidence``) names as computing
    the failing output, when it is a line of ``file`` (the generated node's
    logic.py); ``""`` otherwise."""
    by_id = {o.id: o for o in obligations}
    for e in evidence:
        o = by_id.get(e.obligation)
        cause = str((e.counterexample or {}).get("cause") or "")
        if e.backend == "property_tests" and e.status == "failed" and o is not None and o.node == node \
                and o.guarantee == k and cause.rsplit(":", 1)[0] == file:
            return cause
    return ""


def _generated_handler(ws: Any, node: str, monitoring: MonitoredRun) -> Any:
    """The handler of ``node``'s generated logic.py that published the first
    violating message (:func:`rclverify.diagnosis.handlers.violating_handler`),
    ``None`` for a node without generated code or a run it cannot place."""
    from rclverify.diagnosis.handlers import violating_handler  # deferred: start-up (loads rclverify.diagnosis.handlers, ast only when called)
    entries = [{"backend": x.backend, **dict(x.config)} for x in ws.plan.evidence.get(node, ())]
    return violating_handler(ws.root, node, entries, monitoring)


def _breaking_assignments(ws: Any, program: str, cex: Mapping[str, object], binding: Mapping[str, object],
                          conj: str) -> list[Any]:
    """The last assignments to the outputs ``conj`` reads in the program's
    run on the counterexample (:func:`rclverify.backends.hoare.culprit_assign.breaking_assignments`);
    ``[]`` when the program no longer reads or the run cannot be made."""
    from rclverify.backends.hoare import lang  # deferred: start-up (loads jinja2, z3 and more only when called)
    from rclverify.backends.hoare.culprit_assign import breaking_assignments  # deferred: start-up (loads jinja2, z3 and more only when called)
    outs = {k: str(v) for k, v in binding.items()
            if k.startswith("out.") and re.search(rf"(?<![\w.]){re.escape(k)}(?!\w)", conj)}
    try:
        text = ws.path(program).read_text(encoding="utf-8")
        return breaking_assignments(lang.parse_program(text, program), cex, outs, text)
    except Exception:  # noqa: BLE001 - a program that no longer parses or reads: nothing named
        return []


def _obligation_data(ws: Any, node: str, oid: str) -> Mapping[str, Any]:
    """The backend's ``data`` of obligation ``oid`` of ``node`` (its sealed obligation list's record,
    decoded: :class:`rclverify.records.records.Obligation`); ``{}`` when the list does not hold it or
    holds it in another shape."""
    from rclverify.records.records import Obligation  # deferred: start-up (as below)
    from rclverify.records.sealed import obligation_list  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    records, _ = obligation_list(ws.path(ws.obligations(node)))  # [] when altered outside rclverify
    for o in records or []:
        if isinstance(o, dict) and o.get("id") == oid:
            try:
                return Obligation.from_json(o).data
            except msgspec.ValidationError:
                return {}
    return {}


def _monitors_payload(ws: Any, oid: str) -> MonitorsPayload | None:
    """The monitors' evidence payload of obligation ``oid``, read from its record (the report's row holds
    its ``monitoring`` part only; the repair search needs its ``calls`` too); ``None`` when the record is
    missing, altered or not the monitors' payload."""
    from rclverify.backends.monitors.payload import monitors_payload  # deferred: start-up (a failed monitored run)
    from rclverify.records.store import EvidenceStore  # deferred: start-up (only for a failed monitored run)
    ev, problem = EvidenceStore(ws.root).read(oid)
    return monitors_payload(ev.backend, ev.details) if ev is not None and not problem else None


def _search_inputs(ws: Any, node: str, oid: str) -> dict[str, str] | None:
    """``{workspace path: sha256 of its current text}`` of the files a property test's code repair search
    (:func:`~rclverify.diagnosis.code_repair_check.checked_repairs`) reads: the inputs of the evidence record
    of ``oid`` (the node's snapshot of the contracts and the plan, its implementation's import closure, the
    mapping and the message files it reads; the backend records a run whose closure imports a file outside
    them as inconclusive, never failed) and the node's snapshot.  ``None`` when the record is missing,
    altered or names no input (the repair is then keyed by every contract file and the plan)."""
    from rclverify.records.records import hash_inputs  # deferred: start-up (only for a failed property test)
    from rclverify.records.store import EvidenceStore  # deferred: start-up (only for a failed property test)
    ev, problem = EvidenceStore(ws.root).read(oid)
    if ev is None or problem or not ev.input_hashes:
        return None
    try:
        return hash_inputs(ws.root, [*ev.input_hashes, ws.snapshot(node)])
    except OSError:  # an input gone since the run: the report shows the evidence stale
        return None


def _run_repairs(ws: Any, e: EvidenceRow, node: str, cache: RepairCache) -> MonitorRepairs:
    """The checked code repairs of the failed monitored run ``e`` of ``node`` (:func:`report_repairs`, its
    record's payload and its obligation's ``data``); none (nothing asked) for a run that did not fail or
    whose record is not the monitors' payload."""
    payload = _monitors_payload(ws, e.obligation) if e.status == "failed" else None
    if payload is None:
        return MonitorRepairs()
    return report_repairs(ws, e.obligation, node, _obligation_data(ws, node, e.obligation),
                          payload, cache)


def evidence_record(ws: Any, report: ReportRows, e: EvidenceRow, o: ObligationRow | None,
              cache: RepairCache) -> DiagnosisRow:
    """The diagnosis record (:mod:`rclverify.diagnosis.build`) of the failed
    or erroneous evidence ``e`` of obligation ``o`` (``None``: not in the
    report's obligations): a monitor's first violation, a property test's
    example and code line, a Hoare proof's constants, else the backend's
    explanation; the backends' payloads (``monitoring``, ``counterexample``,
    the obligation's ``data``) are read as the mappings they write."""
    node = o.node if o is not None else e.obligation.split(".", 1)[0]
    k = o.guarantee if o is not None else 0
    backend = e.backend
    text, src = guarantee_source(report, node, k) if k else ("", o.source if o is not None else "")
    where = f"guarantee {k} of {node} ({src})" if k else f"the contract of {node} ({o.source if o is not None else ''})"
    if backend == "hoare" and e.status == "failed" and o is not None:
        return _hoare(ws, report, e, o, cache)
    mon = MonitoredRun.of(e.monitoring)
    fv = mon.first_violation
    if backend == "monitors" and fv is not None:
        gk = fv.guarantee
        gtext, gsrc = guarantee_source(report, node, gk) if gk else ("", "")
        sentence = (f"In {mon.trace if mon.trace is not None else 'the trace'}, the output at {fv.where} (t = {fv.time} s) "
                    f"answering the input at {fv.trigger_where} violates guarantee {gk} of {node} ({gsrc})"
                    f"; {mon.counts.get('violated', '?')} message(s) of the run violate the contract (each: `rclverify explain OBLIGATION#N`).")
        cul: list[Culprit] = [{"what": f"event {fv.where}", "source": fv.where or "", "text": ""},
               {"what": f"guarantee {gk} of {node}", "source": gsrc, "text": gtext}]
        h = _generated_handler(ws, node, mon)  # generated code: the logic.py handler that published it
        if h is not None:
            said = "".join([f"; it returns early at line {', '.join(map(str, h.early))}" if h.early else "",
                            f"; it publishes at line {', '.join(map(str, h.publishes))}" if h.publishes else ""])
            sentence = (sentence + f" The message was published by the handler `{h.name}` of {h.file}:{h.line}, "
                        f"which the generated node.py calls for {h.variable}{said}.")
            cul.insert(0, {"what": f"handler {h.name} of {h.file} (called for {h.variable}{said})",
                           "source": f"{h.file}:{h.line}", "text": h.name})
            # the same guarantee's property test found the line of that logic.py computing the value: it first
            computed = _computed_line(report.obligations, report.evidence, node, gk, h.file)
            if computed:
                sentence = sentence[:-1] + f"; the value it published is computed at {computed} (the property test)."
                cul.insert(0, {"what": f"{computed}: the line where the failing output goes wrong (property test)",
                               "source": computed, "text": ""})
        found = _run_repairs(ws, e, node, cache)
        if found.line and found.repairs:  # the line the first checked repair edits: the slip's
            sentence = sentence[:-1] + f"; the first repair checked on the run edits {found.line}."
            cul.insert(0, {"what": f"{found.line}: the line the first checked repair edits (the node re-run on "
                           "the run's questions)", "source": found.line, "text": ""})
        return diagnosis_record(e.obligation, "monitor", node, e.status, sentence, culprits=cul,
                                counterexample=counterexample_table(fv.values, node), guarantee=gk,
                                repairs=found.repairs, not_offered=[found.why] if found.why else msgspec.UNSET)
    ce = e.counterexample
    if backend == "property_tests" and ce is not None:
        cex = {kk: v for kk, v in ce.items() if kk not in _META_KEYS}
        impl = _obligation_data(ws, node, e.obligation).get("implementation", "the implementation")
        cause = ce.get("cause")  # the implementation line the example takes
        sentence = (f"Hypothesis found inputs on which {impl} "
                    f"violates {where}" + (f"; the implementation line where the failing example goes wrong is {cause}"
                                           if cause else "") + f"; replay: `{ce.get('replay', '')}`.")
        repairs: list[Repair] = []
        if isinstance(cause, str) and cause and e.status == "failed":  # the culprit is a line of the code
            before = {x.obligation: str(x.status) for x in report.evidence if x.obligation.startswith(f"{node}.")}
            # one key per culprit line: the guarantees of a node failing at one line share their repairs
            repairs = cache.get(["code", e.obligation.rsplit(".", 1)[-1], node, cause, before],
                                lambda: checked_repairs(ws, node, e.obligation, cause, before),
                                cause.rpartition(":")[0], _search_inputs(ws, node, e.obligation)) or []
        cul_pt: list[Culprit] = [{"what": where, "source": src, "text": text}]
        made = repaired_line(cause, repairs) if isinstance(cause, str) else ""
        if made:  # the checked repair edits another line of the function: the value is made there
            sentence = (sentence[:-1] + f"; the first checked repair edits {made}, where the wrong value is made "
                        f"({cause} is where the example goes wrong).")
            cul_pt.insert(0, {"what": f"{made}: the line the first checked repair edits", "source": made, "text": ""})
        return diagnosis_record(e.obligation, "property-test", node, e.status, sentence,
                       culprits=cul_pt,
                       counterexample=counterexample_table(cex, node), guarantee=k, repairs=repairs)
    expl = e.explanation
    first = expl.split("; ")[0] if len(expl) > 300 else expl
    return diagnosis_record(e.obligation, "evidence", node, e.status,
                   f"{backend} evidence for {where} is {e.status}: {first}",
                   culprits=[{"what": where, "source": src, "text": text}],
                   counterexample=counterexample_table(e.counterexample, node),
                   guarantee=k)


def _hoare(ws: Any, report: ReportRows, e: EvidenceRow, o: ObligationRow, cache: RepairCache) -> DiagnosisRow:
    from rclverify.backends.hoare import lang  # deferred: start-up (loads jinja2, z3 and more only when called)
    from rclverify.backends.hoare.culprit_lines import compared_constants  # deferred: start-up (loads jinja2, z3 and more only when called)
    node, k = o.node, o.guarantee
    data = _obligation_data(ws, node, e.obligation)
    program = data.get("program", "")
    conj, conj_src = data.get("conjunct_rcl", ""), data.get("conjunct_source", "")
    prog_consts: list[str] = []
    try:
        prog = lang.parse_program(ws.path(program).read_text(encoding="utf-8"), program)
        # the thresholds its conditions compare with, in line order: no assigned constant's line
        compared = compared_constants(prog)
        prog_consts = [f"{program}:{n.loc.line}: {n.text}" for n in compared]
        prog_texts = list(dict.fromkeys(n.text for n in compared))
    except Exception:  # noqa: BLE001 - a program that no longer parses: no constants named
        prog_texts = []
    # the guarantee's thresholds the program does not use (0, a sign bound, is no threshold)
    gtext, gsrc = guarantee_source(report, node, k)
    conj_nums = sorted(set(re.findall(r"(?<![\w.])\d+(?:\.\d+)?(?![\w.])", gtext)) - set(prog_texts) - {"0"},
                       key=float)
    cex = e.counterexample or {}
    table = counterexample_table({kk: v for kk, v in cex.items() if "(final)" not in kk}, node)
    inputs = ", ".join(f"{kk} = {v}" for kk, v in cex.items() if kk.startswith("in."))
    outputs = ", ".join(f"{kk} = {v}" for kk, v in cex.items() if kk.startswith("out."))
    zero = re.search(r"a division by zero on this run \((.+?); verification condition (defined\S*)\)",
                     e.explanation)
    if zero:  # a definedness VC refuted (backends/hoare/defined.py): the division is the culprit, not a constant
        at = re.search(r"division at (\S+?:\d+:\d+)", zero.group(1))
        return diagnosis_record(e.obligation, "hoare", node, e.status,
                       f"{program} can divide by zero under guarantee {k} of {node} ({gsrc}): {zero.group(1)} does "
                       f"not hold on {inputs or 'the counterexample'} (verification condition {zero.group(2)}).",
                       culprits=[{"what": "the division", "source": at.group(1) if at else conj_src,
                                  "text": zero.group(1)}], counterexample=table, guarantee=k)
    sentence = (f"{program} and guarantee {k} of {node} ({gsrc}) disagree on their constants: the program "
                f"compares with {'/'.join(prog_texts) or 'other constants'} (" + ", ".join(prog_consts) + ") where the "
                f"guarantee uses {'/'.join(conj_nums) or 'other constants'}; on {inputs or 'the counterexample'} the "
                f"program gives {outputs or 'another output'}, which the conjunct `{conj}` ({conj_src}) rules out.")
    assigned = [] if (conj_nums and prog_consts) else _breaking_assignments(ws, program, cex, data.get("binding") or {}, conj)
    if assigned:  # no threshold disagrees: the assignment whose value breaks the conjunct
        prog_consts = [f"{program}:{a.line}: {a.text}" for a in assigned]
        sentence = (f"On {inputs or 'the counterexample'} {program} runs "
                    + ", then ".join(f"`{a.text}` ({program}:{a.line})" for a in assigned)
                    + f", giving {outputs or 'its output'}, which the conjunct `{conj}` ({conj_src}) of guarantee "
                    f"{k} of {node} ({gsrc}) rules out: the value assigned there breaks the post-condition.")
    before = {ob.id: ob.status for ob in report.obligations
              if ob.node == node and ob.backend == "hoare" and ob.instance.split(".c")[0] == e.obligation.split(".hoare.", 1)[-1].split(".c")[0]}
    # keyed by what the repair is computed from (not the obligation: every failed triple of one program
    # entry and guarantee gets the same repair, searched once; the case study's c2 and c3)
    reps = cache.get(["hoare", node, k, program, before],
                     lambda: hoare_repair(ws, node, k, program, before), extra_file=program)
    # no change of constants: the one-token corrections of the program, each checked by Z3 the same way
    tokens = [] if reps else cache.get(["hoare-token", node, k, program, before],
                                       lambda: hoare_token_repairs(ws, node, k, program, before),
                                       extra_file=program) or []
    return diagnosis_record(e.obligation, "hoare", node, e.status, sentence,
                   culprits=[{"what": f"{program} line {c.split(':')[1]}", "source": c.split(': ', 1)[0], "text": c.split(': ', 1)[1]}
                             for c in prog_consts] + [{"what": f"conjunct of guarantee {k} of {node}", "source": conj_src, "text": conj}],
                   counterexample=table, repairs=[reps] if reps else tokens, guarantee=k)
