"""``rclverify check``, ``latex`` and ``fmt``: the contracts' text checked, typeset and printed
(docs/rcl-language.md)."""
from __future__ import annotations

import argparse
import sys
from typing import cast

from rclverify.cli.common import AddCommand, emit
from rclverify.lang.errors import RclError


def cmd_check(args: argparse.Namespace) -> int:
    """Parse, type-check and lint ``args.files`` in the scopes of
    :func:`rclverify.model.plan.scopes.group_files` (the plan's system together,
    a replacement contract in its own scope; docs/rcl-language.md).  Every
    scope is checked; exit 1 when one has an error."""
    from rclverify.model.plan.scopes import group_files, plan_diagnostics  # deferred: start-up (imported where it is used)
    from rclverify.lang.filewarn import file_warnings  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.filewarn and more only when called)
    from rclverify.lang.lint import lint  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.lint and more only when called)
    from rclverify.lang.parser import parse_files  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.lang.typecheck import check  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.model.system.services import unserved  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.types and more only when called)
    grouped = group_files(args.files, args.workspace, args.plan)
    for note in grouped.notes:
        print(note, file=sys.stderr)
    from rclverify.lang.errors import Diagnostic  # deferred: start-up (imported where it is used)
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
        from rclverify.semantics.definedness import constant_faults  # deferred: start-up (loads the evaluator only when called)
        errors += constant_faults(checked)  # a constant dividing by zero, at its definition (docs/rcl-language.md)
        warnings += [d for s in specs for d in file_warnings(s)] + [d for s in specs for d in lint(s)]
        from rclverify.model.system.model import unit_diagnostics  # units at both ends of each connection (docs/rcl-language.md); deferred: optional or conditional (inside a block)
        for d in unit_diagnostics(checked):
            (errors if d.severity == "error" else warnings).append(d)
        if scope.why == "the plan's system" or (grouped.plan and len(grouped.scopes) == 1):
            # the plan's statements (formal:, deadline:, ...) against the system they name (docs/requirements.md)
            from rclverify.backends.entry_checks import check_entries  # the evidence entries too (docs/plan.md); deferred: optional or conditional (inside a block)
            found, note = plan_diagnostics(scope.files, checked, args.workspace, args.plan, check_entries)
            errors += [cast(Diagnostic, d) for d in found if getattr(d, "severity", "error") == "error"]
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
    """Print (or write, ``-o FILE``) the contracts of ``args.file`` as LaTeX, type-checked first."""
    from rclverify.lang.latex import to_latex  # deferred: start-up (loads jinja2, rclverify.lang.ast and more only when called)
    from rclverify.lang.parser import parse_file  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.lang.typecheck import check  # deferred: start-up (loads lark, rclverify.core and more only when called)
    spec = parse_file(args.file)
    check([spec])
    return emit(to_latex(spec), args.output)


def cmd_fmt(args: argparse.Namespace) -> int:
    """Print (or write, ``-o FILE``) the contracts of ``args.file`` in canonical RCL."""
    from rclverify.lang.parser import parse_file  # deferred: start-up (loads lark, rclverify.core and more only when called)
    from rclverify.lang.printer import to_rcl  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.printer and more only when called)
    return emit(to_rcl(parse_file(args.file)), args.output)


def add_check(add: AddCommand) -> None:
    """The ``check`` parser."""
    ck = add("check", cmd_check, "parse, type-check and lint RCL files (the plan's contracts together, a "
             "replacement contract in its own scope: docs/rcl-language.md)")
    ck.add_argument("files", nargs="+")
    ck.add_argument("-w", "--workspace", default=".", help="workspace whose plan groups the files (default: .)")
    ck.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")


def add_latex_fmt(add: AddCommand) -> None:
    """The ``latex`` and ``fmt`` parsers."""
    for name, fn, what in (("latex", cmd_latex, "print RCL contracts as LaTeX"),
                           ("fmt", cmd_fmt, "print RCL contracts in canonical form")):
        sp = add(name, fn, what)
        sp.add_argument("file")
        sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of standard output")
