"""``rclverify repair ID [--apply] [--index K]``: a checked repair of the last report, printed, or written
into the workspace and checked again (diagnosis/apply_repair.py; docs/diagnosis.md, "Applying a repair").

Without ``--apply`` nothing is written: the repairs offered for ``ID`` are printed (each its diff, what
checked it and what that shows), or why none is offered.  With ``--apply`` the ``K``-th (default the
first) is written atomically, only over the text it was checked on, and the check that failed is run again
by the pipeline's own stage (:func:`recheck`); its new verdict is printed.

Exit: 0 when the repairs are printed, or when the applied edit's re-check passes; 1 (one located line)
for an unknown id, a report that is missing or of another shape, a file that changed since the check,
``--apply`` with no repair offered, or a re-check that still fails (the edit stays written, the lines say
so); 2 for a usage error.
"""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

from rclverify.cli.common import AddCommand

if TYPE_CHECKING:
    from rclverify.records.problem_rows import DiagnosisRow
    from rclverify.records.repair_rows import RepairRow
    from rclverify.stages.workspace import Workspace

#: Statuses and verdicts of a re-checked item that are a pass.
PASSED = frozenset({"discharged", "ok", "proved"})
#: Diagnosis kinds of a contract health finding (re-checked by the health checks of the node).
HEALTH_KINDS = frozenset({"vacuity", "inconsistency", "unsatisfiable-assumption", "refinement"})


def recheck(ws: "Workspace", diagnosis: "DiagnosisRow", repair: "RepairRow",
            also: Sequence[str] = ()) -> list[tuple[str, str]]:
    """Run again, on the workspace ``ws`` as it is now (the edit made), the check that produced the failing
    record of ``diagnosis``, and of the ids ``also`` of the same kind (the other members of a problem
    asked for by its number): ``[(id, status or verdict), ...]``.

    * evidence (a property test's, a Hoare triple's): every obligation the repair was checked against
      (:func:`~rclverify.diagnosis.apply_repair.obligation_checks`), each run by its backend
      (:func:`rclverify.app.pipeline.stage_run`: Hypothesis, or the Hoare VCs with Z3) and stored;
    * a side condition: the calculus of its node and of every node whose side condition the repair's
      checks name (:func:`~rclverify.app.pipeline.stage_compose`);
    * a health finding: the node's health checks (:func:`~rclverify.app.pipeline.health_findings`);
    * a requirement: the requirements stage; a deadline: the deadlines stage;
    * a unit mismatch: the side conditions it explains (``joins``);
    * a monitored violation: its recorded run judged again with the node re-run from the edited file
      (:func:`~rclverify.diagnosis.monitor_repair.rejudged_applied`; the evidence stays the recorded run's).

    ``[]`` for a kind none of these produced.  Raises ``RclError`` when the edited contracts or plan do
    not check (a located error)."""
    from rclverify.app import pipeline  # deferred: start-up (loads the stages, z3 and the backends)
    from rclverify.diagnosis.apply_repair import obligation_checks  # deferred: start-up (loads z3)
    did, kind, node = diagnosis.id, diagnosis.kind, diagnosis.node
    evidence = obligation_checks(diagnosis, repair)
    if kind == "monitor":  # the recorded run judged again with the node re-run from the edited file
        from rclverify.diagnosis.monitor_repair import rejudged_applied  # deferred: start-up (the re-run)
        from rclverify.runtime.rclpy_source.python import ros2_python  # deferred: start-up (as above)
        return rejudged_applied(ws, diagnosis, repair, ros2_python())
    if evidence:
        return [(oid, str(pipeline.stage_run(ws, oid.split(".", 1)[0], oid).status)) for oid in evidence]
    pipeline.stage_check(ws)
    if kind in HEALTH_KINDS:
        found = {f.id: str(f.status) for f in pipeline.health_findings(ws, node)}
        asked = [did, *also] + [c.check.split(" ")[0] for c in repair.checks]
        return [(i, found[i]) for i in dict.fromkeys(asked) if i in found]
    if kind in ("side-condition", "unit"):
        wanted = [did, *also] if kind == "side-condition" else list(diagnosis.joins or [])
        wanted += [c.check for c in repair.checks]
        wanted = [w for w in dict.fromkeys(wanted) if ".sc" in w]
        out: list[tuple[str, str]] = []
        for n in dict.fromkeys(w.split(".", 1)[0] for w in wanted):
            rows = {str(sc["id"]): str(sc["status"]) for sc in pipeline.stage_compose(ws, n)["side_conditions"]}
            out += [(w, rows[w]) for w in wanted if w in rows]
        return out
    if kind == "requirement":
        return [(str(r["id"]), str(r["verdict"])) for r, _ in pipeline.stage_requirements(ws, force=True)
                if r["id"] == did]
    if kind == "deadline":
        return [(f"{d['requirement']}.deadline", str(d["status"])) for d in pipeline.stage_deadlines(ws)
                if f"{d['requirement']}.deadline" == did]
    return []


def _repair_lines(k: int, n: int, d: "DiagnosisRow", r: "RepairRow") -> list[str]:
    out = [f"repair {k} of {n} for {d.id} ({r.kind}): {r.summary}",
           f"  checked by {r.checked_by}: {r.proves}", f"  not shown: {r.not_shown}"]
    out += [f"  checked: {c.check}: {c.status}" for c in r.checks]
    out += [f"  changes: {c.check}: {c.before} -> {c.after}" for c in r.cost]
    return out + ["  " + line for line in r.diff.rstrip("\n").splitlines()]


def cmd_repair(args: argparse.Namespace) -> int:
    """Print the checked repairs of ``args.id`` in the last report, or with ``args.apply`` write the
    ``args.index``-th and check it again (module docstring).  Returns the exit code."""
    from rclverify.diagnosis.apply_repair import (  # deferred: start-up (loads z3 and the diagnosis)
        NotApplied, apply_repair, changed_lines, find_repairs, none_offered, statuses_before)
    from rclverify.report.explain import id_kinds, near_ids  # deferred: start-up (loads the diagnosis text)
    from rclverify.report.lastrun import located, read_report  # deferred: start-up (loads rclverify.lang.ast)
    from rclverify.cli.common import workspace_of  # deferred: start-up (loads the workspace)
    from rclverify.lang.ast import Loc  # deferred: start-up (loads rclverify.lang.ast, fractions)
    from rclverify.lang.errors import RclError, error  # deferred: start-up (as above)
    root = Path(args.workspace)
    report_path = root / "reports/assurance.json"
    import msgspec  # deferred: start-up (loads msgspec only when called)
    from rclverify.records.report_record import AssuranceReport  # deferred: start-up (the records)
    try:
        report = AssuranceReport.of(read_report(root))
    except msgspec.ValidationError as exc:  # a report of another shape below what read_report checks
        raise located(report_path, f"not an rclverify report: {exc}; run `rclverify verify` (or `doit verify`) "
                                   "to write it again") from None
    found = find_repairs(report, args.id)
    if found is None:
        near = near_ids(report, args.id)
        raise located(report_path, f"no problem {args.id!r} in the last report"
                      + (f"; did you mean {', '.join(near)}?" if near else "")
                      + (f" (ids: {id_kinds(report)})" if id_kinds(report) else ""))
    if not found.offered:
        print(f"{found.subject}: no checked repair is offered")
        print("\n".join(f"  {s}" for s in none_offered(found)))
        if args.apply:
            raise located(report_path, f"{found.subject}: nothing to apply: the last report offers no checked repair")
        return 0
    n = len(found.offered)
    if not 1 <= args.index <= n:
        raise located(report_path, f"{found.subject} has {n} checked repair{'s' if n != 1 else ''}; "
                      f"--index {args.index} is not one of 1..{n}")
    if not args.apply:
        for k, o in enumerate(found.offered, 1):
            print("\n".join(_repair_lines(k, n, o.diagnosis, o.repair)))
        print(f"nothing written; `rclverify repair {args.id} --apply` writes repair {args.index}"
              + (" (--index K another)" if n > 1 else ""))
        return 0
    chosen = found.offered[args.index - 1]
    try:
        path = apply_repair(root, chosen.repair)
    except NotApplied as exc:
        raise RclError([error(Loc(str(root / exc.file), exc.line, exc.col), exc.message, "E-repair")]) from None
    print("\n".join(_repair_lines(args.index, n, chosen.diagnosis, chosen.repair)))
    print(f"applied: {chosen.repair.file} written ({path.stat().st_size} bytes); the check that failed "
          "runs again:")
    also = [d.id for d in found.diagnoses if d.kind == chosen.diagnosis.kind]
    try:
        after = recheck(workspace_of(args), chosen.diagnosis, chosen.repair, also)
    except (RclError, OSError):
        raise  # located lines, or the machine's fault in one line (cli/commands.py)
    except Exception as exc:  # noqa: BLE001 - a backend that fails on the edited code: said, not a traceback
        print(f"the edit is written, but the check could not run again: {type(exc).__name__}: {exc}; "
              "`rclverify verify` runs every check")
        return 1
    if not after:
        print(f"  no stage re-checks a {chosen.diagnosis.kind} problem alone: run `rclverify verify`")
        return 0
    print("\n".join(f"  {line}" for line in changed_lines(statuses_before(report), after)))
    bad = [i for i, s in after if s not in PASSED]
    if bad:
        print(f"the edit is written but {', '.join(bad)} still do{'es' if len(bad) == 1 else ''} not pass")
        return 1
    if chosen.diagnosis.kind == "monitor":
        print("the recorded run passes with the node re-run from the edited file; its evidence stays the recorded "
              "run's until the run is recorded again")
        return 0
    print("every check run again passes; `doit verify` brings the report up to date")
    return 0


def add_repair(add: AddCommand) -> None:
    """The ``repair`` parser."""
    p = add("repair", cmd_repair, "print the checked repairs of a problem of the last report, or apply one "
            "(--apply) and run the failing check again", True)
    p.add_argument("id", help="a problem's id or number, as `rclverify status` and `explain` show them")
    p.add_argument("--apply", action="store_true", help="write the repair (only over the text it was checked "
                   "on) and run the check that failed again")
    p.add_argument("--index", type=int, default=1, help="which repair, 1-based (default: the first)")


__all__ = ["cmd_repair", "add_repair", "recheck"]
