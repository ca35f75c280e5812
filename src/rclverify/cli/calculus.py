"""``rclverify graph``, ``compose``, ``health``, ``export``, ``quotient`` and ``refines``: the system
model, the calculus and contract health printed, obligations exported (docs/calculus.md)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rclverify.cli.common import AddCommand, emit, workspace_of


def cmd_graph(args: argparse.Namespace) -> int:
    """Write the system model as DOT (``-o FILE``, default under artifacts/) and as SVG beside it when
    Graphviz is there and the DOT went to a regular file (never beside a FIFO or device named by ``-o``)."""
    from rclverify.app.pipeline import stage_check, stage_graph  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    from rclverify.core.atomic import atomic_write_text, output_target  # deferred: start-up (loads rclverify.core only when called)
    from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.output and more only when called)
    from rclverify.report.diagram import dot_to_svg  # deferred: start-up (loads jinja2, rclverify.core and more only when called)
    ws = workspace_of(args)
    stage_check(ws)
    dot = stage_graph(ws)
    out = Path(args.output) if args.output else ws.path(ws.DOT)
    if args.output:
        write_atomic(out, dot)  # the path the user named: a device or FIFO written in place, bounded in time
    print(f"DOT: {out}")
    if args.output and output_target(out, named=True) is not None:
        print(f"SVG not written: {out} is not a regular file")
        return 0
    svg = dot_to_svg(dot)
    if svg is not None:
        svg_path = out.with_suffix(".svg")  # not named by the user: a regular file, inside the workspace by default
        atomic_write_text(svg_path, svg, within=None if args.output else ws.root)
        print(f"SVG: {svg_path}")
    else:
        print("graphviz 'dot' not found: SVG not written")
    return 0


def cmd_compose(args: argparse.Namespace) -> int:
    """Apply the calculus to every node and print its rules, side conditions (a counterexample for one not discharged), instances and derived property; exit 1 when a side condition is not discharged."""
    from rclverify.app.pipeline import stage_check, stage_compose  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    ws = workspace_of(args)
    stage_check(ws)
    bad = 0
    for n in ws.node_names():
        c = stage_compose(ws, n)
        print(f"{n}: rules {', '.join(c['rules']) or '(source node)'}; producers {', '.join(c['producers']) or 'none'}")
        for sc in c["side_conditions"]:
            verdict = sc.get("verdict") or sc["status"]
            variant = f" ({sc['variant']})" if verdict == "discharged" and sc.get("variant") else ""
            print(f"  side condition {sc['id']} [{verdict}]{variant}: {sc['conjunct']}  ({sc['source']})")
            ctx = sc.get("context")
            if verdict == "discharged in context":
                used = ctx.get("used_nodes") if ctx else None
                print(f"      upstream guarantees used: {', '.join(used or []) or 'none'} "
                      f"(cone of {ctx.get('cone') if ctx else None} nodes)")
            elif ctx and sc["status"] != "discharged":
                print(f"      checked in context too (cone of {ctx.get('cone')} nodes)"
                      + (f"; assumption violated upstream in the counterexample: {', '.join(ctx['violated'])}"
                         if ctx.get("violated") else ""))
            if sc["status"] != "discharged":
                print(f"      consumer: {n} assumes {sc['conjunct']}")
                for h in sc.get("hypotheses", []):
                    print(f"      producer: {h}")
            if sc["model"]:
                from rclverify.diagnosis.table import counterexample_rows  # deferred: optional or conditional (inside a block)
                from rclverify.report.diagnosis_text import table_lines  # deferred: optional or conditional (inside a block)
                print("      counterexample:")
                print("\n".join(table_lines(counterexample_rows(sc["model"], n), "        ")))
            bad += sc["status"] != "discharged"
        for inst in c["instances"]:
            print(f"  {inst['rule']} instance conclusion: {inst['conclusion']}")
        print(f"  derived property: {c['derived_property']}")
        if c["loop_assumption"]:
            print(f"  note: {c['loop_assumption']}")
    return 1 if bad else 0


def cmd_health(args: argparse.Namespace) -> int:
    """Run the contract health checks of ``args.nodes`` (default: every node) and print each finding; exit 1 on a problem, 2 for an unknown node."""
    from rclverify.app.pipeline import stage_check, stage_health  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    ws = workspace_of(args)
    stage_check(ws)
    problems = 0
    for n in args.nodes or ws.node_names():
        if n not in ws.checked.nodes:
            print(f"error: no node named {n!r}; nodes: {', '.join(ws.node_names())}", file=sys.stderr)
            return 2
        for f in stage_health(ws, n):
            print(f"{f.id} [{f.status}]: {f.message}")
            for c in f.core or []:
                print(f"    core: {c}")
            problems += f.status == "problem"
    return 1 if problems else 0


def cmd_export(args: argparse.Namespace) -> int:
    """Export every node's obligations to the plan's backends and print each one; with a format
    (``export autoware-design -o DIR``), write the workspace in that format instead."""
    if getattr(args, "format", None):
        from rclverify.cli.design import cmd_export_design  # deferred: start-up (loads rclverify.cli.design only when called)
        return cmd_export_design(args)
    from rclverify.app.pipeline import stage_check, stage_export  # deferred: start-up (loads rclverify.app, rclverify.app.pipeline and more only when called)
    ws = workspace_of(args)
    stage_check(ws)
    for n in ws.node_names():
        for o in stage_export(ws, n):
            print(f"{o.id}  [{o.backend}]  {o.artifact or ''}")
    return 0


def cmd_quotient(args: argparse.Namespace) -> int:
    """Print (or write, ``-o FILE``) the weakest contract of ``args.node``
    (:mod:`rclverify.calculus.quotient`); a contract that cannot be given is
    one ``error:`` line, exit 1."""
    from rclverify.calculus.quotient import QuotientError, quotient, render  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.stages.crosscheck.stage import confirm_proof  # each proved re-check confirmed by cvc5 (docs/second-solver.md); deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    ws = Workspace(Path(args.workspace), args.plan, interface_only=(args.node,))
    try:
        q = quotient(ws.checked, ws.model, ws.plan, args.node, confirm=confirm_proof)
    except QuotientError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return emit(render(q), args.output)


def cmd_refines(args: argparse.Namespace) -> int:
    """May the replacement contract replace the original? Z3, each proved side confirmed by cvc5; the exit code of :func:`rclverify.calculus.refinement.refines_main`."""
    from rclverify.calculus.refinement import refines_main  # deferred: start-up (loads lark, yaml and more only when called)
    from rclverify.stages.crosscheck.stage import confirm_proof  # each proved side confirmed by cvc5 (docs/second-solver.md); deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    return refines_main(args.original, args.replacement, assumes=getattr(args, "assume", None) or (),
                        confirm=confirm_proof)


def add_graph_to_export(add: AddCommand) -> None:
    """The ``graph``, ``compose``, ``health`` and ``export`` parsers."""
    add("graph", cmd_graph, "write the system model as Graphviz DOT (and SVG)", True).add_argument("-o", "--output")
    add("compose", cmd_compose, "apply the calculus: side conditions and derived properties", True)
    add("health", cmd_health, "contract consistency and vacuity checks", True).add_argument("nodes", nargs="*")
    from rclverify.cli.design import add_export_format  # deferred: start-up (loads rclverify.cli.design only when called)
    add_export_format(add("export", cmd_export, "export obligations to the plan's backends; with a format, the "
                          "workspace in another tool's format (autoware-design: docs/nodl.md)", True))


def add_quotient_refines(add: AddCommand) -> None:
    """The ``quotient`` and ``refines`` parsers."""
    qt = add("quotient", cmd_quotient, "print the weakest contract of NODE under which its neighbours' side "
             "conditions and its cone's requirements hold, re-checked by Z3 (docs/calculus.md)", True)
    qt.add_argument("node", metavar="NODE", help="a node declared by its interface only, or one to replace")
    qt.add_argument("-o", "--output", metavar="FILE", help="write the contract to FILE instead of standard output")
    r = add("refines", cmd_refines, "check with Z3 that contract B may replace contract A")
    r.add_argument("original", help="FILE.rcl:Node of the contract to replace")
    r.add_argument("replacement", help="FILE.rcl:Node of the replacement contract")
    r.add_argument("--assume", action="append", metavar="FORMULA",
                   help="RCL condition on the replacement's inputs (repeatable); lets it read extra inputs")
