"""One diagnosis record per problem of the report dict.

:func:`diagnose` reads the report dict without diagnoses
(:func:`rclverify.report.build.undiagnosed_report`) and the workspace and
returns ``[record, ...]``, each (the diagnosis stage seals them into
``artifacts/diagnosis/index.json``, :mod:`rclverify.stages.diagnoses`, and
the report reads them from there)::

    {"id": problem id (finding, side condition or obligation id),
     "kind": "vacuity" | "inconsistency" | "unsatisfiable-assumption" | "refinement"
             | "side-condition" | "hoare" | "monitor" | "property-test" | "evidence"
             | "requirement" (a refuted one: diagnosis/requirement.py)
             | "deadline" (a refuted or undecided end-to-end deadline: diagnosis/deadline.py)
             | "unit" (a unit mismatch on a connection, blaming the producer: diagnosis/units.py;
                       with "joins", the ids of the findings it explains, and "lint"),
     "node": str, "status": str,
     "sentence": one sentence naming the culprit by source location,
     "culprits": [{"what": str, "source": "file:line:col", "text": str}],
     "counterexample": [{"node", "variable", "value", "table"}]  (diagnosis.table),
     "repairs": [repair, ...]  (diagnosis.repairs; each checked by Z3, cheapest for the user first),
     "not_offered": [sentences]  (repairs Z3 showed do not work, e.g. a strengthening that
                                  leaves the node unimplementable; side conditions only),
     "related": [ids of other problems of the same node and guarantee]}

Repairs cost Z3 queries (a minute for the case study's Agent), so each
problem's repairs are kept in ``artifacts/cache/diagnosis.pickle`` (:class:`_Cache`)
keyed by everything they are computed from: the problem record, the
contract files, the plan, the program, and the rclverify and Z3 versions.
Deleting the cache is always safe.
"""
from __future__ import annotations

import json
import os
import re
from contextlib import contextmanager
from functools import partial
from typing import Any, Callable, Iterator, Mapping, Sequence

import z3

from rclverify.core.cache import Shelf, file_digest
from rclverify.lang.errors import RclError
from rclverify.diagnosis import blame, repairs as rep
from rclverify.diagnosis.code_repair import checked_repairs, repaired_line
from rclverify.diagnosis.constants import hoare_repair
from rclverify.diagnosis.hoare_tokens import hoare_token_repairs
from rclverify.diagnosis.monitor_repair import report_repairs
from rclverify.diagnosis.deadline import budget_repairs, deadline_record
from rclverify.diagnosis.requirement import requirement_record
from rclverify.diagnosis.sidecond import side_condition_repairs
from rclverify.diagnosis.culprits import culprits, parse_core, plan_facts
from rclverify.records.links import link_pairs
from rclverify.diagnosis.table import counterexample_table
from rclverify.diagnosis.units import unit_records
from rclverify.diagnosis.shapes import ProducerCulprits, ReportRows
from rclverify.records.findings import FindingRow, rows_of
from rclverify.records.report_schema import EvidenceJson, ObligationJson, SideConditionJson
from rclverify.records.stage_records import CexRow, Culprit, DiagnosisEntry, Repair

CACHE = "artifacts/cache/diagnosis.pickle"
#: Taken while diagnosing (:func:`_one_at_a_time`); beside the run lock, not a kept result.
LOCK = "artifacts/diagnosis.lock"
#: Most entries the cache keeps.
KEEP = 200
_META_KEYS = {"conjunct", "facts", "guarantee", "reason", "replay", "source", "cause", "boundary"}


class _Cache:
    """The repairs of this workspace's problems, kept between runs: a
    :class:`~rclverify.core.cache.store.Shelf` of kind ``diagnosis`` (salted with
    Z3's version besides the rclverify code), keyed by the contract and plan
    files' sha256 and the problem's own key.  Keeps what this report used
    and earlier entries up to :data:`KEEP` in all (an edit undone finds them
    again: a repair search costs Z3 seconds)."""

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.shelf = Shelf(ws.path(CACHE), "diagnosis", (f"z3 {z3.get_version_string()}",), keep=KEEP)
        files = sorted({*ws.plan.contracts, ws.plan.file})
        self.base = [f"{rel}\0{file_digest(ws.path(rel))}" for rel in files]

    def get(self, key: Any, make: Callable[[], Any], extra_file: str | None = None) -> Any:
        k = self.shelf.key("repairs", *self.base, json.dumps(key, sort_keys=True, default=str),
                           file_digest(self.ws.path(extra_file)) if extra_file else "")
        got = self.shelf.get(k)
        if got is None:
            try:
                # as JSON gives it back (sorted keys), so a fresh result and a kept one are the same
                # data, key order included (the report's kept pieces are keyed by it: report/fragments.py)
                got = [json.loads(json.dumps(make(), sort_keys=True))]
            except (z3.Z3Exception, RclError, OSError, ValueError, KeyError):
                # a checker that misbehaves gives no repair (and nothing is kept)
                return None
            self.shelf.put(k, got)
        return got[0]

    def save(self) -> None:
        try:
            self.shelf.save()
        except OSError:
            pass  # a pure speed-up


def _guarantee_source(report: ReportRows, node: str, k: int | None) -> tuple[str, str]:
    for n in report["nodes"]:
        if n["name"] == node and k is not None and 1 <= k <= len(n["guarantees"]):
            g = n["guarantees"][k - 1]
            return g["text"], g["source"]
    return "", ""


@contextmanager
def _one_at_a_time(ws: Any) -> Iterator[None]:
    """Hold an exclusive lock on ``artifacts/diagnosis.lock`` (POSIX
    ``flock``; released when the block ends or the process dies).

    Two processes may diagnose the same workspace at once (the diagnosis
    task of ``doit -n 2`` and an ``rclverify report``, or two report parts
    that both found the stage's record stale, :func:`rclverify.app.pipeline.diagnosed`);
    without the lock both computed every repair of a cold run (the case
    study: about 4 CPU seconds each).  With it the second waits, then finds
    the first's repairs in the cache.  Where the
    lock cannot be taken (no ``fcntl``, a read-only workspace) the block
    runs unlocked: the lock only saves work."""
    try:
        import fcntl  # deferred: optional or conditional (inside a block)
        path = ws.path(LOCK)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except (ImportError, OSError):
        yield
        return
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:
            pass
        yield
    finally:
        os.close(fd)  # releases the lock


def diagnose(ws: Any, report: ReportRows) -> list[DiagnosisEntry]:
    """The diagnosis records of every problem of ``report`` (see the module
    docstring), in the order of the report's problems list: health
    findings, side conditions, evidence.  One process at a time per
    workspace (:func:`_one_at_a_time`), so parallel report tasks compute
    each repair once."""
    with _one_at_a_time(ws):
        return _diagnose(ws, report)


def _diagnose(ws: Any, report: ReportRows) -> list[DiagnosisEntry]:
    cache = _Cache(ws)
    out: list[DiagnosisEntry] = []
    health_by_node: dict[str, dict[str, str]] = {}
    findings = rows_of(report["findings"])
    for f in findings:
        health_by_node.setdefault(f.node, {})[f.id] = f.status
    # which guarantees of a node each culprit guarantee makes vacuous (one guard repair for all of them)
    victims: dict[tuple[str, int], list[tuple[int, int | None]]] = {}
    for f in findings:
        fk = f.guarantee
        if f.status == "problem" and f.check == "non-vacuous" and fk is not None:  # a guarantee's check
            vac = sorted(int(x) for x, st in (f.instances or {}).items() if st == "vacuous")
            victim = (fk, vac[0] if vac else None)  # where it was vacuous
            for m in culprits(parse_core(f.core), fk):
                if m.kind == "guarantee" and victim not in victims.setdefault((f.node, m.index), []):
                    victims[(f.node, m.index)].append(victim)

    def guard(node: str, c: int) -> Repair | None:
        vs = sorted(victims.get((node, c), []), key=lambda v: v[0])
        found: Repair | None = cache.get(["guard", node, c, vs, health_by_node.get(node, {})],
                                                 lambda: rep.guard_repair(ws, node, c, vs,
                                                                          health_by_node.get(node, {})))
        return found

    # a unit mismatch on a connection first: it explains the side condition and the runs that follow from it
    out += unit_records(ws, report, cache.get)
    for f in findings:
        if f.status != "problem":
            continue
        out.append(_finding(ws, report, f, guard))
    sc_before = {sc["id"]: sc["status"] for sc in report["side_conditions"]}
    for sc in report["side_conditions"]:
        if sc["status"] in ("failed", "inconclusive"):
            out.append(_side_condition(ws, report, sc, cache, sc_before))
    for q in report.get("requirements", []):
        # a requirement refuted only by its end-to-end deadline is the deadline's problem (below), not its formula's
        own = (q.get("without_deadline") or {}).get("verdict", q.get("verdict")) if q.get("deadline") else q.get("verdict")
        if q.get("verdict") == "refuted" and own == "refuted":
            out.append(requirement_record(ws, report, q, cache, _guarantee_source))
    for row in report.get("deadlines") or ():
        if row.get("verdict") in ("refuted", "inconclusive"):
            chain = row.get("chain")
            key = ["deadline", row["requirement"], row.get("path"), row.get("within"),
                   [[h["node"], h["guarantee"], h["within_s"]] for h in chain] if chain else chain]
            reps: list[Repair] = ((cache.get(key, partial(budget_repairs, ws, row)) or [])
                                  if row["verdict"] == "refuted" else [])
            out.append(deadline_record(ws, report, row, reps))
    obligations = {o["id"]: o for o in report["obligations"]}
    for e in report["evidence"]:
        if e["status"] in ("failed", "error"):
            out.append(_evidence(ws, report, e, obligations.get(e["obligation"]), cache))
    # the same node and guarantee found by several techniques: each record names the others
    by_key: dict[tuple[str, Any], list[str]] = {}
    for d in out:
        by_key.setdefault((d["node"], d.get("guarantee")), []).append(d["id"])
    for d in out:
        d["related"] = [x for x in by_key[(d["node"], d.get("guarantee"))] if x != d["id"]] if d.get("guarantee") else []
    cache.save()
    return out


def _record(id: str, kind: str, node: str, status: str, sentence: str, *, culprits: list[Culprit] | None = None,
            counterexample: list[CexRow] | None = None, repairs: Sequence[Repair | None] = (),
            guarantee: int | None = None) -> DiagnosisEntry:
    """A diagnosis record (module docstring); ``related`` is filled in by :func:`_diagnose`."""
    return {"id": id, "kind": kind, "node": node, "status": status, "sentence": sentence,
            "culprits": culprits if culprits is not None else [],
            "counterexample": counterexample if counterexample is not None else [],
            "repairs": [r for r in repairs if r], "guarantee": guarantee, "related": []}


def _finding(ws: Any, report: ReportRows, f: FindingRow, guard: Callable[[str, int], Repair | None]) -> DiagnosisEntry:
    node, k = f.node, f.guarantee
    facts = plan_facts(ws, node)
    members = parse_core(f.core, facts)
    table = counterexample_table(f.model, node)
    if f.check == "non-vacuous":
        text, src = _guarantee_source(report, node, k)
        cs = culprits(members, k)
        names = [m.name() for m in cs]
        sentence = (f"Guarantee {k} of {node} ({src}) can never fire"
                    + (f" for {_after(f.message, ' is vacuous for ', ':')}" if " is vacuous for " in f.message else "")
                    + ": " + (_and(names) + (" exclude" if len(names) > 1 else " excludes") + " its premise"
                              if names else "its premise contradicts the node's contract") + ".")
        reps = [guard(node, m.index) for m in cs if m.kind == "guarantee"]
        kind = "vacuity"
    elif f.check in ("contract-consistent", "assumption-satisfiable"):
        names = [m.name() for m in members]
        kind = "inconsistency" if f.check == "contract-consistent" else "unsatisfiable-assumption"
        what = "contract" if kind == "inconsistency" else "assumption"
        sentence = (f"The {what} of {node} cannot hold: " + (_and(names) + " contradict each other" if names
                                                               else "Z3 found no way to satisfy it") + ".")
        cs = members
        reps = [guard(node, m.index) for m in members if m.kind == "guarantee"] if kind == "inconsistency" else []
    else:
        cs, reps, kind = [], [], "refinement" if f.check == "replacement-refines" else f.check
        sentence = f.message + (" " + f.explanation if f.explanation else "")
    return _record(f.id, kind, node, "failed", sentence,
                   culprits=[{"what": m.name(), "source": m.source, "text": m.text} for m in cs],
                   counterexample=table, repairs=[r for r in reps if r], guarantee=k)


def _after(text: str, start: str, stop: str) -> str:
    return text.split(start, 1)[1].split(stop, 1)[0]


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _side_condition(ws: Any, report: ReportRows, sc: SideConditionJson, cache: _Cache,
                    sc_before: Mapping[str, str]) -> DiagnosisEntry:
    pairs = link_pairs(sc)
    cul: list[Culprit] = [{"what": f"assumption of {sc['node']}: `{sc['conjunct']}`", "source": sc["source"], "text": sc["conjunct"]}]
    said = []
    # a producer guarantee is named only when strengthening it discharges the side condition (blame.py)
    def find() -> ProducerCulprits:
        found, undecided = blame.side_condition_culprits(ws, sc)
        return {"culprits": [list(x) for x in found], "undecided": undecided}
    got: ProducerCulprits | None = \
        cache.get(["sc-culprits", sc["id"], sc["conjunct"]], find) if sc["status"] == "failed" else None
    shown: ProducerCulprits = got or {"culprits": [], "undecided": 1}
    blamed = {(str(p), int(k)) for p, k in shown["culprits"]}
    for p, ov, _, _ in pairs:
        for n in report["nodes"]:
            if n["name"] != p:
                continue
            for g in n["guarantees"]:
                if not re.search(rf"out\.{re.escape(ov)}(?!\w)", g["text"]):
                    continue
                if sc["status"] == "failed" and (p, int(g["index"])) not in blamed:
                    continue
                if any(c["source"] == g["source"] for c in cul):
                    continue
                cul.append({"what": f"guarantee {g['index']} of {p}: `{g['text']}`", "source": g["source"],
                            "text": g["text"]})
                said.append(f"{p}'s guarantee {g['index']} ({g['source']}) `{g['text']}`")
    involved = {str(sc["node"])} | {p for p, _, _, _ in pairs}
    table = [r for r in counterexample_table(sc.get("model"), sc["node"]) if str(r["node"]) in involved]
    cex = ", ".join(f"{r['node']}.{r['variable']} = {r['value']}" for r in table)
    together = ("its producers' guarantees (Z3 could not show which)" if shown["undecided"]
                else "its producers' guarantees (together: strengthening any one of them alone does not discharge it)")
    sentence = (f"{sc['node']} assumes `{sc['conjunct']}` ({sc['source']}), but "
                + (_and(said) if said else together)
                + (" allows" if len(said) == 1 else " allow") + " values outside it"
                + (f": Z3's counterexample {cex}" if cex else "") + ".")
    if sc["status"] == "inconclusive":
        sentence = f"Z3 could not decide whether {sc['node']}'s assumption `{sc['conjunct']}` ({sc['source']}) follows from " \
                   + (_and(said) if said else "its producers' guarantees") + "."
    # what a weakened assumption of the consumer invalidates: its evidence, established under the old one
    evidence = [f"{o['id']} ({o['status']})" for o in report["obligations"] if o["node"] == sc["node"]]
    found = (cache.get(["side-condition", sc["id"], sc["conjunct"], dict(sc_before), evidence],
                       lambda: side_condition_repairs(ws, sc, sc_before, evidence)) or {}) if sc["status"] == "failed" else {}
    rec = _record(sc["id"], "side-condition", sc["node"], sc["status"], sentence, culprits=cul,
                  counterexample=table, repairs=list(found.get("repairs") or []))
    rec["not_offered"] = list(found.get("not_offered") or [])
    return rec


def _computed_line(report: ReportRows, node: str, k: object, file: str) -> str:
    """``file:line`` a failed property test of guarantee ``k`` of ``node``
    names as computing the failing output, when it is a line of ``file``
    (the generated node's logic.py); ``""`` otherwise."""
    obligations = {str(o["id"]): o for o in report.get("obligations") or ()}
    for e in report.get("evidence") or ():
        o = obligations.get(str(e["obligation"]))
        cause = str((e.get("counterexample") or {}).get("cause") or "") if isinstance(e.get("counterexample"), dict) else ""
        if e.get("backend") == "property_tests" and e.get("status") == "failed" and o is not None and o["node"] == node \
                and o["guarantee"] == k and cause.rsplit(":", 1)[0] == file:
            return cause
    return ""


def _generated_handler(ws: Any, node: str, monitoring: Mapping[str, object]) -> Any:
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


def _obligation_record(ws: Any, node: str, oid: str) -> Mapping[str, Any]:
    from rclverify.records.sealed import obligation_list  # deferred: start-up (loads rclverify.records, rclverify.records.records and more only when called)
    records, _ = obligation_list(ws.path(ws.obligations(node)))  # [] when altered outside rclverify
    for o in records or []:
        if isinstance(o, dict) and o.get("id") == oid:
            return dict(o)
    return {}


def _evidence(ws: Any, report: ReportRows, e: EvidenceJson, o: ObligationJson | None,
              cache: _Cache) -> DiagnosisEntry:
    node = o["node"] if o is not None else e["obligation"].split(".", 1)[0]
    k = o["guarantee"] if o is not None else 0
    backend = e["backend"]
    text, src = _guarantee_source(report, node, k) if k else ("", o["source"] if o is not None else "")
    where = f"guarantee {k} of {node} ({src})" if k else f"the contract of {node} ({o['source'] if o is not None else ''})"
    if backend == "hoare" and e["status"] == "failed" and o is not None:
        return _hoare(ws, report, e, o, cache)
    mon = e.get("monitoring") or {}
    fv = mon.get("first_violation") if isinstance(mon, dict) else None
    if backend == "monitors" and fv:
        gk = fv.get("guarantee")
        gtext, gsrc = _guarantee_source(report, node, gk) if gk else ("", "")
        sentence = (f"In {mon.get('trace', 'the trace')}, the output at {fv.get('where')} (t = {fv.get('time')} s) "
                    f"answering the input at {fv.get('trigger_where')} violates guarantee {gk} of {node} ({gsrc})"
                    f"; {mon.get('counts', {}).get('violated', '?')} message(s) of the run violate the contract (each: `rclverify explain OBLIGATION#N`).")
        cul: list[Culprit] = [{"what": f"event {fv.get('where')}", "source": fv.get("where", ""), "text": ""},
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
            computed = _computed_line(report, node, gk, h.file)
            if computed:
                sentence = sentence[:-1] + f"; the value it published is computed at {computed} (the property test)."
                cul.insert(0, {"what": f"{computed}: the line where the failing output goes wrong (property test)",
                               "source": computed, "text": ""})
        found = report_repairs(ws, e["obligation"], node, _obligation_record(ws, node, e["obligation"]).get("data")
                               or {}, mon, cache) if e["status"] == "failed" else {}
        if found.get("line") and found.get("repairs"):  # the line the first checked repair edits: the slip's
            sentence = sentence[:-1] + f"; the first repair checked on the run edits {found['line']}."
            cul.insert(0, {"what": f"{found['line']}: the line the first checked repair edits (the node re-run on "
                           "the run's questions)", "source": found["line"], "text": ""})
        rec = _record(e["obligation"], "monitor", node, e["status"], sentence, culprits=cul,
                      counterexample=counterexample_table(fv.get("values"), node), guarantee=gk,
                      repairs=list(found.get("repairs") or []))
        if found.get("why"):
            rec["not_offered"] = [str(found["why"])]
        return rec
    ce = e.get("counterexample")
    if backend == "property_tests" and isinstance(ce, dict):
        cex = {kk: v for kk, v in ce.items() if kk not in _META_KEYS}
        impl = _obligation_record(ws, node, e["obligation"]).get("data", {}).get("implementation", "the implementation")
        cause = ce.get("cause")  # the implementation line the example takes
        sentence = (f"Hypothesis found inputs on which {impl} "
                    f"violates {where}" + (f"; the implementation line where the failing example goes wrong is {cause}"
                                           if cause else "") + f"; replay: `{ce.get('replay', '')}`.")
        repairs: list[Repair] = []
        if isinstance(cause, str) and cause and e["status"] == "failed":  # the culprit is a line of the code
            before = {str(x["obligation"]): str(x["status"]) for x in report["evidence"]
                      if str(x["obligation"]).startswith(f"{node}.")}
            # one key per culprit line: the guarantees of a node failing at one line share their repairs
            repairs = cache.get(["code", e["obligation"].rsplit(".", 1)[-1], node, cause, before],
                                lambda: checked_repairs(ws, node, e["obligation"], cause, before),
                                cause.rpartition(":")[0]) or []
        cul_pt: list[Culprit] = [{"what": where, "source": src, "text": text}]
        made = repaired_line(cause, repairs) if isinstance(cause, str) else ""
        if made:  # the checked repair edits another line of the function: the value is made there
            sentence = (sentence[:-1] + f"; the first checked repair edits {made}, where the wrong value is made "
                        f"({cause} is where the example goes wrong).")
            cul_pt.insert(0, {"what": f"{made}: the line the first checked repair edits", "source": made, "text": ""})
        return _record(e["obligation"], "property-test", node, e["status"], sentence,
                       culprits=cul_pt,
                       counterexample=counterexample_table(cex, node), guarantee=k, repairs=repairs)
    expl = str(e.get("explanation", ""))
    first = expl.split("; ")[0] if len(expl) > 300 else expl
    return _record(e["obligation"], "evidence", node, e["status"],
                   f"{backend} evidence for {where} is {e['status']}: {first}",
                   culprits=[{"what": where, "source": src, "text": text}],
                   counterexample=counterexample_table(e.get("counterexample") if isinstance(e.get("counterexample"), dict) else None, node),
                   guarantee=k)


def _hoare(ws: Any, report: ReportRows, e: EvidenceJson, o: ObligationJson, cache: _Cache) -> DiagnosisEntry:
    from rclverify.backends.hoare import lang  # deferred: start-up (loads jinja2, z3 and more only when called)
    from rclverify.backends.hoare.culprit_lines import compared_constants  # deferred: start-up (loads jinja2, z3 and more only when called)
    node, k = o["node"], o["guarantee"]
    rec = _obligation_record(ws, node, e["obligation"])
    data = rec.get("data", {})
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
    gtext, gsrc = _guarantee_source(report, node, k)
    conj_nums = sorted(set(re.findall(r"(?<![\w.])\d+(?:\.\d+)?(?![\w.])", gtext)) - set(prog_texts) - {"0"},
                       key=float)
    cex = e.get("counterexample") or {}
    table = counterexample_table({kk: v for kk, v in cex.items() if "(final)" not in kk}, node)
    inputs = ", ".join(f"{kk} = {v}" for kk, v in cex.items() if kk.startswith("in."))
    outputs = ", ".join(f"{kk} = {v}" for kk, v in cex.items() if kk.startswith("out."))
    zero = re.search(r"a division by zero on this run \((.+?); verification condition (defined\S*)\)",
                     str(e.get("explanation", "")))
    if zero:  # a definedness VC refuted (backends/hoare/defined.py): the division is the culprit, not a constant
        at = re.search(r"division at (\S+?:\d+:\d+)", zero.group(1))
        return _record(e["obligation"], "hoare", node, e["status"],
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
    before = {ob["id"]: ob["status"] for ob in report["obligations"]
              if ob["node"] == node and ob["backend"] == "hoare" and ob["instance"].split(".c")[0] == e["obligation"].split(".hoare.", 1)[-1].split(".c")[0]}
    # keyed by what the repair is computed from (not the obligation: every failed triple of one program
    # entry and guarantee gets the same repair, searched once; the case study's c2 and c3)
    reps = cache.get(["hoare", node, k, program, before],
                     lambda: hoare_repair(ws, node, k, program, before), extra_file=program)
    # no change of constants: the one-token corrections of the program, each checked by Z3 the same way
    tokens = [] if reps else cache.get(["hoare-token", node, k, program, before],
                                       lambda: hoare_token_repairs(ws, node, k, program, before),
                                       extra_file=program) or []
    return _record(e["obligation"], "hoare", node, e["status"], sentence,
                   culprits=[{"what": f"{program} line {c.split(':')[1]}", "source": c.split(': ', 1)[0], "text": c.split(': ', 1)[1]}
                             for c in prog_consts] + [{"what": f"conjunct of guarantee {k} of {node}", "source": conj_src, "text": conj}],
                   counterexample=table, repairs=[reps] if reps else tokens, guarantee=k)
