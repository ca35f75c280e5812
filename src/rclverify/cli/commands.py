"""The ``rclverify`` command line.

``rclverify check FILE...``        parse, type-check and lint RCL files
``rclverify latex FILE``           print the contracts as LaTeX
``rclverify fmt FILE``             print the contracts in canonical RCL
``rclverify graph``                write the system model as DOT (and SVG)
``rclverify compose``              apply the calculus and print side conditions
``rclverify health [NODE...]``     contract consistency and vacuity findings
``rclverify export``               export obligations to the plan's backends
``rclverify report [--no-wait]``   rebuild reports/ from the artifacts (waits for a run in progress)
``rclverify requirements``         check each formal requirement with Z3 and print its status
``rclverify verify [--strict] [--no-wait]``  the whole pipeline through doit (one run at a time per workspace)
``rclverify status``               the last run's summary and problems, running nothing
``rclverify explain ID``           what the last report says of any id an output shows
``rclverify refines A.rcl:N B.rcl:M``  may contract M replace contract N?
``rclverify quotient NODE [-o FILE]``  the weakest contract of NODE its neighbours need
``rclverify init DIR [--nodes A,B]``  write a new workspace that verifies at once
``rclverify bundle [-o FILE]``     the assessor's bundle; ``--verify FILE`` checks one
``rclverify review NODE [-o FILE]``  write a review record to fill in
``rclverify ros scan PATH...``     the ROS computation graph from workspaces (docs/ros.md)
``rclverify ros check``            the plan's contracts against that graph
``rclverify lsp``                  the RCL language server over stdio (docs/editor.md)

Exit codes: 0 success, 1 errors in the input (or, for ``compose``/``verify
--strict``, an obligation that does not hold), 2 usage errors.  A user's
mistake prints ``file:line:col: error: message`` lines, never a traceback.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from contextlib import contextmanager
from typing import Any, Callable, Iterator, Sequence

from rclverify.lang.errors import RclError


def seconds(text: str) -> float:
    """argparse type of a duration option: a finite number of seconds >= 0
    (``nan``, ``inf`` and negative values are usage errors, exit 2)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not (value >= 0 and value != float("inf")):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number of seconds >= 0")
    return value


def _print_diags(exc: RclError) -> int:
    for d in exc.diagnostics:
        print(d, file=sys.stderr)
    return 1


def cmd_check(args: argparse.Namespace) -> int:
    """Parse, type-check and lint ``args.files`` in the scopes of
    :func:`rclverify.model.plan.scopes.group_files` (the plan's system together,
    a replacement contract in its own scope; docs/rcl-language.md).  Every
    scope is checked; exit 1 when one has an error."""
    from rclverify.model.plan.scopes import group_files, plan_diagnostics
    from rclverify.lang.filewarn import file_warnings
    from rclverify.lang.lint import lint
    from rclverify.lang.parser import parse_files
    from rclverify.lang.typecheck import check
    from rclverify.model.system.services import unserved
    grouped = group_files(args.files, args.workspace, args.plan)
    for note in grouped.notes:
        print(note, file=sys.stderr)
    from rclverify.lang.errors import Diagnostic
    errors: list[Diagnostic] = []
    warnings: list[Diagnostic] = []
    for scope in grouped.scopes:
        if scope.why and len(grouped.scopes) > 1:
            print(f"{', '.join(scope.files)}: {scope.why}")
        try:
            specs = parse_files(scope.files)
            checked = check(specs)
        except RclError as exc:
            errors += exc.diagnostics
            continue
        warnings += [d for s in specs for d in file_warnings(s)] + [d for s in specs for d in lint(s)]
        from rclverify.model.system.model import unit_diagnostics  # units at both ends of each connection (docs/rcl-language.md)
        for d in unit_diagnostics(checked):
            (errors if d.severity == "error" else warnings).append(d)
        if scope.why == "the plan's system" or (grouped.plan and len(grouped.scopes) == 1):
            # the plan's statements (formal:, deadline:, ...) against the system they name (docs/requirements.md)
            from rclverify.backends.entry_checks import check_entries  # the evidence entries too (docs/plan.md)
            found, note = plan_diagnostics(scope.files, checked, args.workspace, args.plan, check_entries)
            errors += [d for d in found if getattr(d, "severity", "error") == "error"]
            if note:
                print(note, file=sys.stderr)
        warnings += unserved(checked)  # a call no node of the scope answers (W-unserved)
    if errors:  # the located errors only, as for one scope
        for d in errors:
            print(d, file=sys.stderr)
        return 1
    for d in warnings:
        print(d)
    print(f"{len(args.files)} file(s): 0 errors, {len(warnings)} warning(s)")
    return 0


def cmd_latex(args: argparse.Namespace) -> int:
    from rclverify.lang.latex import to_latex
    from rclverify.lang.parser import parse_file
    from rclverify.lang.typecheck import check
    spec = parse_file(args.file)
    check([spec])
    return _emit(to_latex(spec), args.output)


def cmd_fmt(args: argparse.Namespace) -> int:
    from rclverify.lang.parser import parse_file
    from rclverify.lang.printer import to_rcl
    return _emit(to_rcl(parse_file(args.file)), args.output)


def _emit(text: str, output: str | None) -> int:
    """Write ``text`` to stdout, or atomically to the file ``output``
    (``-o FILE``; a write error is a located ``E-io`` error, exit 1)."""
    if output is None:
        print(text, end="")
        return 0
    from rclverify.lang.output import write_atomic
    write_atomic(Path(output), text)
    return 0


def _ws(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    from rclverify.app.pipeline import Workspace
    return Workspace(Path(args.workspace), args.plan)


def cmd_graph(args: argparse.Namespace) -> int:
    from rclverify.app.pipeline import stage_check, stage_graph
    from rclverify.report.diagram import dot_to_svg
    ws = _ws(args)
    stage_check(ws)
    dot = stage_graph(ws)
    out = Path(args.output) if args.output else ws.path(ws.DOT)
    if args.output:
        out.write_text(dot, encoding="utf-8")
    print(f"DOT: {out}")
    svg = dot_to_svg(dot)
    if svg is not None:
        svg_path = out.with_suffix(".svg")
        svg_path.write_text(svg, encoding="utf-8")
        print(f"SVG: {svg_path}")
    else:
        print("graphviz 'dot' not found: SVG not written")
    return 0


def cmd_compose(args: argparse.Namespace) -> int:
    from rclverify.app.pipeline import stage_check, stage_compose
    ws = _ws(args)
    stage_check(ws)
    bad = 0
    for n in ws.node_names():
        c = stage_compose(ws, n)
        print(f"{n}: rules {', '.join(c['rules']) or '(source node)'}; producers {', '.join(c['producers']) or 'none'}")
        for sc in c["side_conditions"]:
            verdict = sc.get("verdict") or sc["status"]
            variant = f" ({sc['variant']})" if verdict == "discharged" and sc.get("variant") else ""
            print(f"  side condition {sc['id']} [{verdict}]{variant}: {sc['conjunct']}  ({sc['source']})")
            ctx = sc.get("context") or {}
            if verdict == "discharged in context":
                print(f"      upstream guarantees used: {', '.join(ctx.get('used_nodes') or []) or 'none'} "
                      f"(cone of {ctx.get('cone')} nodes)")
            elif ctx and sc["status"] != "discharged":
                print(f"      checked in context too (cone of {ctx.get('cone')} nodes)"
                      + (f"; assumption violated upstream in the counterexample: {', '.join(ctx['violated'])}"
                         if ctx.get("violated") else ""))
            if sc["status"] != "discharged":
                print(f"      consumer: {n} assumes {sc['conjunct']}")
                for h in sc.get("hypotheses", []):
                    print(f"      producer: {h}")
            if sc["model"]:
                from rclverify.diagnosis.table import counterexample_table
                from rclverify.diagnosis.text import table_lines
                print("      counterexample:")
                print("\n".join(table_lines(counterexample_table(sc["model"], n), "        ")))
            bad += sc["status"] != "discharged"
        for inst in c["instances"]:
            print(f"  {inst['rule']} instance conclusion: {inst['conclusion']}")
        print(f"  derived property: {c['derived_property']}")
        if c["loop_assumption"]:
            print(f"  note: {c['loop_assumption']}")
    return 1 if bad else 0


def cmd_health(args: argparse.Namespace) -> int:
    from rclverify.app.pipeline import stage_check, stage_health
    ws = _ws(args)
    stage_check(ws)
    problems = 0
    for n in args.nodes or ws.node_names():
        if n not in ws.checked.nodes:
            print(f"error: no node named {n!r}; nodes: {', '.join(ws.node_names())}", file=sys.stderr)
            return 2
        for f in stage_health(ws, n):
            print(f"{f['id']} [{f['status']}]: {f['message']}")
            for c in f["core"] or []:
                print(f"    core: {c}")
            problems += f["status"] == "problem"
    return 1 if problems else 0


def cmd_export(args: argparse.Namespace) -> int:
    from rclverify.app.pipeline import stage_check, stage_export
    ws = _ws(args)
    stage_check(ws)
    for n in ws.node_names():
        for o in stage_export(ws, n):
            print(f"{o['id']}  [{o['backend']}]  {o['artifact'] or ''}")
    return 0


def cmd_requirements(args: argparse.Namespace) -> int:
    """Check the requirements (only those whose inputs changed, unless
    ``--force``) and print each with its status; exit 1 when one is refuted,
    proved from an inconsistency or inconclusive."""
    from rclverify.cli.requirements import show_requirements
    from rclverify.app.pipeline import stage_check, stage_requirements
    ws = _ws(args)
    stage_check(ws)
    stage_requirements(ws, force=args.force)
    return show_requirements(ws, sys.stdout)


def cmd_deadlines(args: argparse.Namespace) -> int:
    """Decide every requirement's end-to-end deadline (rule D3,
    calculus/deadlines.py), write ``artifacts/deadlines/index.json`` (the
    stage's sealed record, stages/deadlines.py) and print
    each result; exit 1 when one is refuted or inconclusive."""
    from rclverify.stages.deadlines import stage_deadlines
    from rclverify.calculus.deadlines import PROVED, show
    from rclverify.app.pipeline import stage_check
    ws = _ws(args)
    stage_check(ws)  # the snapshots the record's inputs name
    results, records = stage_deadlines(ws)
    sys.stdout.write(json.dumps(records, indent=2) + "\n" if args.json else show(results))
    return 0 if all(r.status == PROVED for r in results) else 1


@contextmanager
def _run_lock(args: argparse.Namespace) -> Iterator[None]:
    """Hold the workspace's run lock (:mod:`rclverify.core.runlock`) for the block:
    a command that writes ``reports/`` or reads the evidence as a whole
    (``report``, ``bundle``) waits for a ``doit verify`` in progress, which
    would otherwise rewrite them under it.  ``--no-wait``/``RCLVERIFY_NO_WAIT=1``
    make it exit 1 instead (:class:`~rclverify.core.runlock.RunInProgress`,
    printed by :func:`main`).  Released at the end of the block; a lock this
    process already held stays held."""
    from rclverify.core import runlock
    root = Path(args.workspace)
    took = False
    # no workspace or no plan: the command fails with its own located error, and no
    # artifacts/run.lock is made where there is no workspace
    if root.is_dir() and (root / args.plan).is_file():
        try:
            took = runlock.acquire(root, wait=False if getattr(args, "no_wait", False) else None)
        except PermissionError:  # a read-only artifacts/: no rclverify run can write there either
            took = False
    try:
        yield
    finally:
        if took:
            runlock.release(root)


def cmd_report(args: argparse.Namespace) -> int:
    from rclverify.app.pipeline import stage_report
    with _run_lock(args):
        report, paths = stage_report(_ws(args))
    for p in paths:
        print(p)
    print(report["summary"]["headline"])
    return 0


def cmd_verify(args: argparse.Namespace) -> int:
    from rclverify.app.tasks import DEP_FILE, build_tasks, doit_config
    if not Path(args.workspace).is_dir():  # before doit opens its state file there (a sqlite3 traceback)
        print(f"{args.workspace}: error: no such workspace directory", file=sys.stderr)
        return 1
    if not (Path(args.workspace) / args.plan).is_file():
        # a missing plan: the located error `compose` gives, not doit's DependencyError
        _ws(args).plan
    try:  # takes the workspace's run lock: waits for a run in progress unless --no-wait
        tasks = build_tasks(Path(args.workspace), args.plan, wait=False if args.no_wait else None)
    except SystemExit as exc:  # build_tasks printed the one-line reason
        return int(exc.code) if isinstance(exc.code, int) else 1
    module = type(sys)("rclverify_dodo")
    module.__dict__.update(tasks)
    module.DOIT_CONFIG = doit_config(str(Path(args.workspace) / DEP_FILE))  # type: ignore[attr-defined]
    argv = ["verify"] + (["--strict"] if args.strict else [])
    if args.jobs > 1:
        argv = ["-n", str(args.jobs)] + argv
    try:  # SystemExit: a fault while doit saves its state, already reported in one line (tasks._guard_dep_writes)
        return _run_doit(module, argv, args.cluster)
    except SystemExit as exc:
        return int(exc.code) if isinstance(exc.code, int) else 1
    finally:  # the run lock, also when doit ended before completing the run (in-process callers go on)
        from rclverify.core.runlock import release
        release(Path(args.workspace))


def _run_doit(module: object, argv: list[str], cluster: str | None) -> int:
    from doit.cmd_base import ModuleTaskLoader
    from doit.doit_cmd import DoitMain
    if not cluster:
        return int(DoitMain(ModuleTaskLoader(module)).run(argv))
    from rclverify.app.cluster import CLUSTER_ENV  # read by the evidence tasks, also in doit's worker processes
    before = os.environ.get(CLUSTER_ENV)
    os.environ[CLUSTER_ENV] = cluster
    try:
        return int(DoitMain(ModuleTaskLoader(module)).run(argv))
    finally:
        if before is None:
            del os.environ[CLUSTER_ENV]
        else:
            os.environ[CLUSTER_ENV] = before


def _io_error(path: Path, message: str) -> Any:
    from rclverify.lang.ast import Loc
    from rclverify.lang.errors import error
    return error(Loc(str(path), 1, 1), message, "E-io")


def cmd_status(args: argparse.Namespace) -> int:
    """Print the last run's overall line, problems (ROS grounding errors
    among them), requirements line and summary table from
    ``artifacts/report/summary.json`` (the JSON report when there is none);
    runs nothing.  Exit 0; 1 (one located line) when neither is there or the
    file read is of another shape (:mod:`rclverify.report.lastrun`)."""
    from rclverify.report.summary import print_last_run
    print_last_run(Path(args.workspace))
    return 0


def cmd_explain(args: argparse.Namespace) -> int:
    """Print what the last JSON report (``reports/assurance.json``) says of
    ``args.id``: any id an output shows (:mod:`rclverify.report.explain`:
    requirement, node, guarantee, obligation, side condition, health check,
    diagnosis, problem number, SARIF rule, ROS or lint code, argument
    element).  Exit 0; 1 (one located line, with the closest ids) for an
    unknown id or a report of another shape."""
    from rclverify.report.explain import explain, id_kinds, near_ids
    from rclverify.report.lastrun import located, read_report
    root = Path(args.workspace)
    report = read_report(root)
    extra = []
    for name in ("reports/assurance.sarif", "reports/argument.json"):
        try:  # optional: their ids are looked up when they are there and readable
            extra.append(json.loads((root / name).read_text(encoding="utf-8")))
        except (OSError, ValueError):
            extra.append(None)
    try:
        lines = explain(report, args.id, *extra)
        near = [] if lines is not None else near_ids(report, args.id, *extra)
    except (KeyError, TypeError, AttributeError, ValueError) as exc:  # a deeper field of another shape
        raise located(root / "reports/assurance.json", f"not an rclverify report: cannot read it ({exc!r}); "
                      "run `rclverify verify` (or `doit verify`) to write it again") from None
    if lines is None:  # an unverified guarantee, a derived property: a finding with no record of its own
        from rclverify.diagnosis.text import finding_lines
        lines = finding_lines(report, args.id) or None
    if lines is not None:
        print("\n".join(lines))
        return 0
    hint = f"; did you mean {', '.join(near)}?" if near else ""
    kinds = id_kinds(report)
    raise located(root / "reports/assurance.json", f"no problem or obligation {args.id!r} in the last report, "
                  f"nor any other id it shows{hint}"
                  + (f" (ids: {kinds})" if kinds else " (it has no requirement, node or problem)"))


def cmd_cache(args: argparse.Namespace) -> int:
    """List what the workspace keeps between runs under ``artifacts/cache``
    (:func:`rclverify.core.cache.kept_files`: file, kind, entries, size, whether
    this rclverify code wrote it), or delete it all with ``--clear`` (always
    safe: every entry is a pure speed-up).  Exit 0; 1 (located) for a
    missing workspace."""
    import shutil

    from rclverify.core.cache import CACHE_DIR, kept_files
    root = Path(args.workspace)
    if not root.is_dir():
        raise RclError([_io_error(root, "no such workspace directory")])
    if args.clear:
        shutil.rmtree(root / CACHE_DIR, ignore_errors=True)
        print(f"{CACHE_DIR}: cleared")
        return 0
    rows = kept_files(root)
    if not rows:
        print(f"{CACHE_DIR}: empty")
    for r in rows:
        entries = "" if r["entries"] is None else f"{r['entries']} files"
        current = {True: "current", False: "other code: not used", None: ""}[r["current"]]
        print(f"{r['file']:<48} {r['kind'] or '?':<18} {r['bytes'] / 1024:>9.1f} KiB  {entries:<10} {current}")
    print("Why a task ran again, or did not: `doit info TASK` in the workspace (docs/scale.md).")
    return 0


def cmd_init(args: argparse.Namespace) -> int:
    if getattr(args, "from_ros", None):
        from rclverify.cli.ros import init_from_ros
        return init_from_ros(args)
    from rclverify.tools.scaffold import InitError, init_workspace
    names = [n.strip() for n in args.nodes.split(",")] if args.nodes is not None else None
    try:
        written = init_workspace(Path(args.dir), names)
    except InitError as exc:
        print(f"{args.dir}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except OSError as exc:
        print(f"{args.dir}: error: cannot write the workspace: {exc.strerror or exc}", file=sys.stderr)
        return 1
    for p in written:
        print(p)
    print(f"workspace written; run `doit verify` in {args.dir}")
    return 0


def _report_out_of_date(ws: Any) -> list[str]:
    """Why the written report no longer says what the recorded artifacts say
    (:func:`rclverify.report.bundle.fresh.report_out_of_date`)."""
    from rclverify.report.bundle.fresh import report_out_of_date
    return report_out_of_date(ws)


def cmd_bundle(args: argparse.Namespace) -> int:
    """Write the assessor's bundle, or (``--verify FILE``) check one against its manifest."""
    from rclverify.report.bundle.archive import verify_bundle, write_bundle
    from rclverify.report.bundle.manifest import BundleError
    if args.recheck:
        return _bundle_recheck(args.recheck)
    from rclverify.report.bundle import signature
    if args.keygen:
        try:
            public = signature.write_key_pair(Path(args.keygen))
        except BundleError as exc:
            print(f"rclverify bundle: error: {exc.problems[0]}", file=sys.stderr)
            return 1
        print(f"{args.keygen}: private key (keep it); {public}: public key, fingerprint "
              f"{signature.fingerprint(signature.load_public_key(public))} (give it to the assessor to pin)")
        return 0
    if args.verify:
        try:
            key = signature.load_public_key(Path(args.key)) if args.key else None
            manifest = verify_bundle(Path(args.verify), key=key)
        except BundleError as exc:
            for problem in exc.problems:
                print(f"{args.verify}: error: {problem}", file=sys.stderr)
            return 1
        signed = (f"; signed by the pinned key {manifest['signed']}" if manifest["signed"] else
                  "; no key pinned (--key AUTHOR.pub): the seals prove the records unchanged since sealing, not "
                  "who sealed them")
        print(f"{args.verify}: {len(manifest['files'])} file(s) match MANIFEST.json; every record's seal holds"
              + signed)
        return 0
    ws = _ws(args)
    with _run_lock(args):  # the report and the evidence it is checked against, as one run left them
        problems = _report_out_of_date(ws)
        if problems:
            for problem in problems:
                print(f"{args.workspace}: error: {problem}", file=sys.stderr)
            return 1
        name = "".join(c if c.isalnum() or c in "-_." else "-"
                       for c in (ws.plan.name or ws.root.resolve().name)).strip("-")
        out = Path(args.output) if args.output else Path(f"{name or 'workspace'}-bundle.tar.gz")
        try:
            key = signature.load_private_key(Path(args.sign)) if args.sign else None
            manifest = write_bundle(ws.root, ws.plan, out, key=key)
        except BundleError as exc:
            for problem in exc.problems:
                print(f"{args.workspace}: error: {problem}", file=sys.stderr)
            return 1
    for m in manifest["missing"]:
        print(f"warning: {m}: named by the plan but does not exist; not in the bundle", file=sys.stderr)
    print(f"{out}: {len(manifest['files'])} file(s) and MANIFEST.json; check with: rclverify bundle --verify {out}")
    return 0


def _bundle_recheck(archive: str) -> int:
    """``bundle --recheck``: re-decide every stored query of ``archive`` with both solvers (docs/second-solver.md)."""
    from rclverify.report.bundle.archive import scan_members
    from rclverify.report.bundle.manifest import BundleError
    from rclverify.stages.crosscheck.recheck import recheck_members
    records: dict[str, bytes] = {}
    try:  # streamed under --verify's limits and member-name rules; only the records kept (issue 63, row 8)
        scan_members(Path(archive), None, records)
        out = recheck_members(records)
    except BundleError as exc:
        for problem in exc.problems:
            print(f"{archive}: error: {problem}", file=sys.stderr)
        return 1
    for n in out.notes:
        print(f"{archive}: note: {n}", file=sys.stderr)
    for p in out.problems:
        print(f"{archive}: error: {p}", file=sys.stderr)
    if out.problems:
        return 1
    print(f"{archive}: {out.checked} discharging quer{'y' if out.checked == 1 else 'ies'} re-decided from the "
          "bundle alone; every answer agrees with its record")
    return 0


def cmd_review(args: argparse.Namespace) -> int:
    from rclverify.backends.review.blank import blank_record
    from rclverify.records.store import atomic_write_text
    from rclverify.app.pipeline import Workspace
    root = Path(args.workspace)
    out_rel = ""
    if args.output:  # the record this command writes may be the one the plan names and misses (issue 48)
        try:
            out_rel = Path(args.output).resolve().relative_to(root.resolve()).as_posix()
        except ValueError:
            out_rel = ""
    ws = Workspace(root, args.plan, missing_ok=(out_rel,) if out_rel else ())
    if args.node not in ws.checked.nodes:
        print(f"error: no node named {args.node!r}; nodes: {', '.join(ws.node_names())}", file=sys.stderr)
        return 2
    try:
        text = blank_record(ws.checked.nodes[args.node], ws.root, args.files)
    except FileNotFoundError as exc:
        print(f"error: cannot read reviewed file {exc}", file=sys.stderr)
        return 1
    if args.output:
        atomic_write_text(Path(args.output), text)
        print(f"review record to fill in: {args.output}")
    else:
        print(text, end="")
    return 0


def cmd_refines(args: argparse.Namespace) -> int:
    from rclverify.calculus.refinement import refines_main
    from rclverify.stages.crosscheck.stage import confirm_proof  # each proved side confirmed by cvc5 (docs/second-solver.md)
    return refines_main(args.original, args.replacement, assumes=getattr(args, "assume", None) or (),
                        confirm=confirm_proof)


def cmd_quotient(args: argparse.Namespace) -> int:
    """Print (or write, ``-o FILE``) the weakest contract of ``args.node``
    (:mod:`rclverify.calculus.quotient`); a contract that cannot be given is
    one ``error:`` line, exit 1."""
    from rclverify.calculus.quotient import QuotientError, quotient, render
    from rclverify.stages.crosscheck.stage import confirm_proof  # each proved re-check confirmed by cvc5 (docs/second-solver.md)
    from rclverify.app.pipeline import Workspace
    ws = Workspace(Path(args.workspace), args.plan, interface_only=(args.node,))
    try:
        q = quotient(ws.checked, ws.model, ws.plan, args.node, confirm=confirm_proof)
    except QuotientError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return _emit(render(q), args.output)


def cmd_monitor(args: argparse.Namespace) -> int:
    from rclverify.cli.monitor import monitor_command
    from rclverify.app.pipeline import Workspace
    checked = Workspace(Path(args.workspace), args.plan).checked  # raises RclError, printed located by main
    return monitor_command(args, checked)


def cmd_oracle(args: argparse.Namespace) -> int:
    from rclverify.cli.monitor import oracle_command
    from rclverify.app.pipeline import Workspace
    checked = Workspace(Path(args.workspace), args.plan).checked  # raises RclError, printed located by main
    return oracle_command(args, checked)


#: Exit code when standard output's reader left (128 + SIGPIPE, what a
#: command killed by SIGPIPE reports in a shell).
BROKEN_PIPE_EXIT = 141


def _reader_left() -> int:
    """Standard output's pipe closed (``rclverify explain ID | head``): point
    standard output at the null device, so that the interpreter's flush at exit
    neither fails nor prints, and return :data:`BROKEN_PIPE_EXIT`.  Nothing
    goes to standard error: the reader asked for no more (POSIX ``SIGPIPE``
    semantics; the Python documentation of ``signal``, "Note on SIGPIPE")."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # no file descriptor behind sys.stdout (a test's capture)
        pass
    return BROKEN_PIPE_EXIT


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rclverify`` console script; returns the exit code."""
    p = argparse.ArgumentParser(prog="rclverify", description="Compositional verification from RCL contracts.")
    from rclverify import __version__
    p.add_argument("--version", action="version", version=f"rclverify {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    def add(name: str, fn: Callable[[argparse.Namespace], int], help: str, workspace: bool = False) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help, description=help)
        sp.set_defaults(fn=fn)
        if workspace:
            sp.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
            sp.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
        return sp

    ck = add("check", cmd_check, "parse, type-check and lint RCL files (the plan's contracts together, a "
             "replacement contract in its own scope: docs/rcl-language.md)")
    ck.add_argument("files", nargs="+")
    ck.add_argument("-w", "--workspace", default=".", help="workspace whose plan groups the files (default: .)")
    ck.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    for name, fn, what in (("latex", cmd_latex, "print RCL contracts as LaTeX"),
                           ("fmt", cmd_fmt, "print RCL contracts in canonical form")):
        sp = add(name, fn, what)
        sp.add_argument("file")
        sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of standard output")
    add("graph", cmd_graph, "write the system model as Graphviz DOT (and SVG)", True).add_argument("-o", "--output")
    add("compose", cmd_compose, "apply the calculus: side conditions and derived properties", True)
    add("health", cmd_health, "contract consistency and vacuity checks", True).add_argument("nodes", nargs="*")
    add("export", cmd_export, "export obligations to the plan's backends", True)
    rep = add("report", cmd_report, "rebuild the assurance report from the artifacts", True)
    add("requirements", cmd_requirements, "check each formal requirement with Z3 from the composed contracts and "
        "print its status", True).add_argument("--force", action="store_true", help="check every requirement again")
    add("deadlines", cmd_deadlines, "decide each requirement's end-to-end deadline with Z3 (deadlines add along "
        "the path)", True).add_argument("--json", action="store_true", help="print the results as JSON")
    add("cache", cmd_cache, "list what the workspace keeps between runs (artifacts/cache), or clear it",
        True).add_argument("--clear", action="store_true", help="delete artifacts/cache (always safe)")
    add("status", cmd_status, "print the last run's summary and problems (runs nothing)", True)
    add("explain", cmd_explain, "print what the last report says of an id: a requirement, node, guarantee "
        "(Agent.g3), problem, obligation, side condition, health check, SARIF rule or ROS code", True).add_argument(
        "id", help="any id an output shows (`rclverify status` lists the problems and their findings)")
    v = add("verify", cmd_verify, "run the whole pipeline with doit", True)
    v.add_argument("--strict", action="store_true",
                   help="exit 1 unless every obligation, side condition and health check holds")
    v.add_argument("-n", "--jobs", type=int, default=1, help="parallel doit processes")
    v.add_argument("--no-wait", action="store_true",
                   help="exit 1 instead of waiting when another run is in progress in the workspace "
                        "(also: RCLVERIFY_NO_WAIT=1)")
    v.add_argument("--cluster", metavar="ADDRESS",
                   help="send backend jobs to the Dask scheduler at ADDRESS (e.g. tcp://127.0.0.1:8786); "
                        "default: run them locally")
    i = add("init", cmd_init, "write a new workspace (dodo.py, example contracts, plan) that verifies at once")
    i.add_argument("dir", help="directory to create (must be new or empty)")
    i.add_argument("--nodes", help="comma-separated node names, in chain order (default: Sensor,Controller,Actuator)")
    i.add_argument("--from-ros", metavar="PATH", action="append",
                   help="one contract skeleton per node of the ROS workspace PATH (repeatable; docs/ros.md)")
    i.add_argument("--launch", action="append", default=[], metavar="FILE",
                   help="with --from-ros: entry launch file (repeatable)")
    i.add_argument("--library-endpoints", action="store_true",
                   help="with --from-ros: also make the libraries' endpoints (tf, bond, diagnostics, interactive "
                        "markers) contract inputs and outputs; by default they are listed apart")
    bnd = add("bundle", cmd_bundle, "write the assessor's bundle (reports, artifacts, plan, contracts, manifest)", True)
    bnd.add_argument("-o", "--output", help="archive to write (.tar.gz or .zip; default: <workspace name>-bundle.tar.gz)")
    bnd.add_argument("--verify", metavar="FILE", help="check the archive FILE against its manifest instead")
    bnd.add_argument("--sign", metavar="KEY",
                     help="sign the manifest with the Ed25519 private key KEY (PEM; MANIFEST.sig in the archive)")
    bnd.add_argument("--key", metavar="PUB",
                     help="with --verify: the author's pinned Ed25519 public key (PEM); the signature must hold")
    bnd.add_argument("--keygen", metavar="KEY",
                     help="write a new Ed25519 key pair KEY and KEY.pub instead, for --sign and --key")
    bnd.add_argument("--recheck", metavar="FILE",
                     help="re-decide every stored query of the archive FILE with Z3 and cvc5 from the bundle "
                          "alone and compare with the recorded verdicts instead")
    for sp in (rep, bnd):
        sp.add_argument("--no-wait", action="store_true",
                        help="exit 1 instead of waiting when a run is in progress in the workspace "
                             "(also: RCLVERIFY_NO_WAIT=1)")
    rv = add("review", cmd_review, "write a review record to fill in for NODE (checklist from its guarantees)", True)
    rv.add_argument("node")
    rv.add_argument("-o", "--output", help="write the record to this file instead of standard output")
    rv.add_argument("-f", "--files", nargs="*", default=[], help="reviewed files (workspace-relative), listed with their sha256")
    qt = add("quotient", cmd_quotient, "print the weakest contract of NODE under which its neighbours' side "
             "conditions and its cone's requirements hold, re-checked by Z3 (docs/calculus.md)", True)
    qt.add_argument("node", metavar="NODE", help="a node declared by its interface only, or one to replace")
    qt.add_argument("-o", "--output", metavar="FILE", help="write the contract to FILE instead of standard output")
    r = add("refines", cmd_refines, "check with Z3 that contract B may replace contract A")
    r.add_argument("original", help="FILE.rcl:Node of the contract to replace")
    r.add_argument("replacement", help="FILE.rcl:Node of the replacement contract")
    r.add_argument("--assume", action="append", metavar="FORMULA",
                   help="RCL condition on the replacement's inputs (repeatable); lets it read extra inputs")

    from rclverify.cli.ros import add_parsers as add_ros_parsers
    add_ros_parsers(sub)
    from rclverify.cli.generate import add_parsers as add_generate_parsers
    add_generate_parsers(sub)
    from rclverify.cli.lsp import add_parsers as add_lsp_parsers
    add_lsp_parsers(sub)
    m = add("monitor", cmd_monitor, "check recorded runs (ROSMonitoring logs, ROS bags) against every "
            "node's contract", True)
    m.add_argument("traces", nargs="*", metavar="TRACE", help="a .jsonl log, a .bag, a ROS 2 bag directory or .mcap")
    m.add_argument("--mapping", help="mapping file (default: backends/monitors/mapping.yaml if present)")
    m.add_argument("--horizon", type=seconds, help="seconds an input event may wait for its answer (default 5.0)")
    m.add_argument("--json", action="store_true", help="print the verdicts as JSON")
    m.add_argument("--strict", action="store_true",
                   help="exit 1 also when a node, topic, service, action or deadline of the contracts was not "
                        "judged (nothing heard, not decoded, ...; docs/monitors.md, \"Silence is never green\")")
    lv = m.add_argument_group("live monitoring (ROS 1, ROS 2 over DDS; docs/monitors.md)")
    lv.add_argument("--live", action="store_true", help="monitor the running ROS system instead (ROS 1: "
                    "ROS_MASTER_URI; ROS 2: --ros2)")
    lv.add_argument("--log", default="monitor_live.jsonl", help="JSON-lines log of events and verdicts to write")
    lv.add_argument("--evidence", help="write the monitoring evidence record (JSON) here when stopped")
    lv.add_argument("--forward", action="append", default=[], metavar="SVC=REAL",
                    help="serve SVC (a service a contract serves) and forward each call to REAL, checking its "
                         "deadline (repeatable; docs/monitors.md, \"Services, actions and deadlines\")")
    lv.add_argument("--interfaces", action="append", default=[], metavar="DIR",
                    help="directory of <pkg>/srv and <pkg>/action files (workspace-relative; repeatable)")
    lv.add_argument("--duration", type=seconds, help="stop after this many seconds (default: at SIGINT/SIGTERM)")
    lv.add_argument("--reorder-window", type=seconds, default=0.05, help="seconds to wait for stamp ordering")
    lv.add_argument("--silence", type=seconds, default=10.0,
                    help="report a contract topic not received for this many seconds (default 10; 0: off)")
    lv.add_argument("--status", type=seconds, default=1.0, help="seconds between status lines (0: off)")
    lv.add_argument("--verdict-topic", default="/rclverify/verdict", help="topic of the per-event verdicts")
    lv.add_argument("--node", dest="nodes", action="append", metavar="NODE", help="monitor only NODE (repeatable)")
    lv.add_argument("--ros", choices=("1", "2"), help="ROS version (default: $ROS_VERSION, else 1)")
    lv.add_argument("--ros2", dest="ros", action="store_const", const="2",
                    help="ROS 2 over DDS (Cyclone DDS; ROS_DOMAIN_ID, CYCLONEDDS_URI): same as --ros 2")
    lv.add_argument("--enforce", action="append", default=[], metavar="TOPIC[:=PRIVATE][@open]",
                    help="ROS 2: republish TOPIC only when the guarantee holds; the node publishes on PRIVATE "
                         "(default TOPIC_unchecked); TOPIC@open also releases what cannot be decided, which is "
                         "held back by default (repeatable)")
    lv.add_argument("--record", metavar="BAG", help="ROS 2: record the contract topics to a new ROS 2 bag")
    lv.add_argument("--record-storage", choices=("sqlite3", "mcap"),
                    help="the bag's storage (default: mcap for a BAG ending .mcap, else sqlite3)")
    o = add("oracle", cmd_oracle, "serve the contracts as a ROSMonitoring oracle over WebSocket", True)
    o.add_argument("--port", type=int, default=8080, help="TCP port (default 8080)")
    o.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    o.add_argument("--node", dest="nodes", action="append", metavar="NODE", help="serve only NODE (repeatable)")
    o.add_argument("--mapping", help="mapping file (default: backends/monitors/mapping.yaml if present)")
    o.add_argument("--horizon", type=seconds, help="seconds an input event may wait for its answer")
    args = p.parse_args(argv)
    from rclverify.core.runlock import RunInProgress
    try:
        code = int(args.fn(args))
        if not sys.stdout.closed:  # the language server closes its stdout at `exit`
            sys.stdout.flush()  # a closed pipe shows here, not at exit, where it could not be caught
        return code
    except BrokenPipeError:  # `rclverify explain ID | head`: the reader left; end quietly
        return _reader_left()
    except RclError as exc:
        return _print_diags(exc)
    except RunInProgress as exc:  # report/bundle --no-wait while a run holds the workspace
        print(f"{args.workspace}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except OSError as exc:  # a fault of the machine (read-only directory, full disk): one plain line
        from rclverify.core.faults import describe_os_error
        root = getattr(args, "workspace", None)
        print(describe_os_error(exc, Path(root).resolve() if root else None), file=sys.stderr)
        return 1
    except RecursionError:
        # Last line of defence: the parser bounds nesting (lang/parser.py
        # NESTING_LIMIT), so this means a stage built a deeper formula itself.
        print(f"error: {args.command}: input too deeply nested for this stage", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
