"""The ``rclverify`` command line.

``rclverify check FILE...``        parse, type-check and lint RCL files
``rclverify latex FILE``           print the contracts as LaTeX
``rclverify fmt FILE``             print the contracts in canonical RCL
``rclverify graph``                write the system model as DOT (and SVG)
``rclverify compose``              apply the calculus and print side conditions
``rclverify health [NODE...]``     contract consistency and vacuity findings
``rclverify export``               export obligations to the plan's backends
``rclverify report``               rebuild reports/ from the artifacts
``rclverify verify [--strict]``    the whole pipeline through doit
``rclverify refines A.rcl:N B.rcl:M``  may contract M replace contract N?

Exit codes: 0 success, 1 errors in the input (or, for ``compose``/``verify
--strict``, an obligation that does not hold), 2 usage errors.  A user's
mistake prints ``file:line:col: error: message`` lines, never a traceback.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable, Sequence

from .rcl.errors import RclError


def _print_diags(exc: RclError) -> int:
    for d in exc.diagnostics:
        print(d, file=sys.stderr)
    return 1


def cmd_check(args: argparse.Namespace) -> int:
    from .rcl.lint import lint
    from .rcl.parser import parse_files
    from .rcl.typecheck import check
    specs = parse_files(args.files)
    check(specs)
    warnings = [d for s in specs for d in lint(s)]
    for d in warnings:
        print(d)
    print(f"{len(args.files)} file(s): 0 errors, {len(warnings)} warning(s)")
    return 0


def cmd_latex(args: argparse.Namespace) -> int:
    from .rcl.latex import to_latex
    from .rcl.parser import parse_file
    from .rcl.typecheck import check
    spec = parse_file(args.file)
    check([spec])
    print(to_latex(spec), end="")
    return 0


def cmd_fmt(args: argparse.Namespace) -> int:
    from .rcl.parser import parse_file
    from .rcl.printer import to_rcl
    print(to_rcl(parse_file(args.file)), end="")
    return 0


def _ws(args: argparse.Namespace):  # type: ignore[no-untyped-def]
    from .pipeline import Workspace
    return Workspace(Path(args.workspace), args.plan)


def cmd_graph(args: argparse.Namespace) -> int:
    from .pipeline import stage_check
    from .report.diagram import dot_to_svg
    ws = _ws(args)
    stage_check(ws)
    dot = ws.path(ws.DOT).read_text(encoding="utf-8")
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
    from .pipeline import stage_check, stage_compose
    ws = _ws(args)
    stage_check(ws)
    bad = 0
    for n in ws.node_names():
        c = stage_compose(ws, n)
        print(f"{n}: rules {', '.join(c['rules']) or '(source node)'}; producers {', '.join(c['producers']) or 'none'}")
        for sc in c["side_conditions"]:
            print(f"  side condition {sc['id']} [{sc['status']}]: {sc['conjunct']}")
            if sc["model"]:
                for k, v in sc["model"].items():
                    print(f"      {k} = {v}")
            bad += sc["status"] != "discharged"
        for inst in c["instances"]:
            print(f"  {inst['rule']} instance conclusion: {inst['conclusion']}")
        print(f"  derived property: {c['derived_property']}")
        if c["loop_assumption"]:
            print(f"  note: {c['loop_assumption']}")
    return 1 if bad else 0


def cmd_health(args: argparse.Namespace) -> int:
    from .pipeline import stage_check, stage_health
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
    from .pipeline import stage_check, stage_export
    ws = _ws(args)
    stage_check(ws)
    for n in ws.node_names():
        for o in stage_export(ws, n):
            print(f"{o['id']}  [{o['backend']}]  {o['artifact'] or ''}")
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    from .report.build import build_report
    from .report.render import render_all
    ws = _ws(args)
    report = build_report(ws)
    for p in render_all(report, ws.path("reports")):
        print(p)
    print(report["summary"]["headline"])
    return 0


def cmd_verify(args: argparse.Namespace) -> int:
    from doit.cmd_base import ModuleTaskLoader
    from doit.doit_cmd import DoitMain
    from .tasks import build_tasks
    tasks = build_tasks(Path(args.workspace), args.plan)
    module = type(sys)("rclverify_dodo")
    module.__dict__.update(tasks)
    module.DOIT_CONFIG = {"verbosity": 2, "dep_file": str(Path(args.workspace) / ".doit.db")}  # type: ignore[attr-defined]
    argv = ["verify"] + (["--strict"] if args.strict else [])
    if args.jobs > 1:
        argv = ["-n", str(args.jobs)] + argv
    return int(DoitMain(ModuleTaskLoader(module)).run(argv))


def cmd_refines(args: argparse.Namespace) -> int:
    from .calculus.refinement import refines_main
    return refines_main(args.original, args.replacement, assumes=getattr(args, "assume", None) or ())


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rclverify`` console script; returns the exit code."""
    p = argparse.ArgumentParser(prog="rclverify", description="Compositional verification from RCL contracts.")
    sub = p.add_subparsers(dest="command", required=True)

    def add(name: str, fn: Callable[[argparse.Namespace], int], help: str, workspace: bool = False) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help, description=help)
        sp.set_defaults(fn=fn)
        if workspace:
            sp.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
            sp.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
        return sp

    add("check", cmd_check, "parse, type-check and lint RCL files").add_argument("files", nargs="+")
    add("latex", cmd_latex, "print RCL contracts as LaTeX").add_argument("file")
    add("fmt", cmd_fmt, "print RCL contracts in canonical form").add_argument("file")
    add("graph", cmd_graph, "write the system model as Graphviz DOT (and SVG)", True).add_argument("-o", "--output")
    add("compose", cmd_compose, "apply the calculus: side conditions and derived properties", True)
    add("health", cmd_health, "contract consistency and vacuity checks", True).add_argument("nodes", nargs="*")
    add("export", cmd_export, "export obligations to the plan's backends", True)
    add("report", cmd_report, "rebuild the assurance report from the artifacts", True)
    v = add("verify", cmd_verify, "run the whole pipeline with doit", True)
    v.add_argument("--strict", action="store_true",
                   help="exit 1 unless every obligation, side condition and health check holds")
    v.add_argument("-n", "--jobs", type=int, default=1, help="parallel doit processes")
    r = add("refines", cmd_refines, "check with Z3 that contract B may replace contract A")
    r.add_argument("original", help="FILE.rcl:Node of the contract to replace")
    r.add_argument("replacement", help="FILE.rcl:Node of the replacement contract")
    r.add_argument("--assume", action="append", metavar="FORMULA",
                   help="RCL condition on the replacement's inputs (repeatable); lets it read extra inputs")

    args = p.parse_args(argv)
    try:
        return int(args.fn(args))
    except RclError as exc:
        return _print_diags(exc)
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
