"""``rclverify import autoware-design`` and ``rclverify export autoware-design``: Autoware System Designer
designs read into a workspace and written from one (docs/nodl.md, "Autoware System Designer").

``rclverify import autoware-design DIR -o WS``   the design's contracts, plan and NoDL documents written
                                                 into WS (the design copied to WS/design unless it lies in
                                                 WS; the plan's ``design`` key names it; an existing plan
                                                 keeps its other content), then its monitoring fields
                                                 decided against them
``rclverify import autoware-design DIR --check [-w WS]``  only decide them against WS as it stands
``rclverify export autoware-design [-w WS] -o DIR``        the workspace written as a design

Exit codes: 0 nothing refuted; 1 a field refuted (``design-*`` errors), a file that cannot be read
(located ``file:line:col: error:`` lines, printed by ``rclverify``'s main) or a file that exists and
is not overwritten without ``--force``; 2 usage errors.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

#: The formats ``import`` and ``export`` know.
FORMATS = ("autoware-design",)
#: The plan ``import`` writes (or, when it exists, whose ``design`` key it sets).
PLAN = "contracts/plan.yaml"


def add_import(sub: Any) -> None:
    """Add the ``import`` command with its ``autoware-design`` subcommand."""
    g = sub.add_parser("import", help="read another tool's files into a workspace: autoware-design (docs/nodl.md), "
                                      "fret (docs/requirements.md)",
                       description="Read another tool's design files into a workspace (docs/nodl.md)")
    gs = g.add_subparsers(dest="import_format", required=True)
    a = gs.add_parser("autoware-design", help="an Autoware System Designer design folder (*.node.yaml, "
                                              "*.module.yaml, *.system.yaml) as contracts, plan and NoDL documents")
    a.add_argument("design", metavar="DIR", help="the design folder (every design file under it is read)")
    a.add_argument("-o", "--output", metavar="WS", help="the workspace written (contracts/, nodl/, dodo.py)")
    a.add_argument("--check", action="store_true", help="write nothing: decide the design's timeouts and rates "
                                                        "against the workspace -w as it stands")
    a.add_argument("-w", "--workspace", default=".", help="--check: the workspace (default: .)")
    a.add_argument("--plan", default="contracts/plan.yaml", help="--check: plan file, relative to the workspace")
    a.add_argument("--system", metavar="NAME", help="the system to flatten when the folder holds several")
    a.add_argument("--force", action="store_true", help="overwrite files that exist (default: refuse)")
    a.set_defaults(fn=cmd_import)
    from rclverify.cli.fret import add_fret  # deferred: start-up (loads rclverify.cli.fret only when called)
    add_fret(gs)  # rclverify import fret EXPORT.json (docs/requirements.md, "Requirements from FRET")


def add_export_format(p: argparse.ArgumentParser) -> None:
    """Give the ``export`` command its optional format (``rclverify export autoware-design -o DIR``)."""
    p.add_argument("format", nargs="?", choices=FORMATS, help="write the workspace in another tool's format "
                                                              "instead of exporting obligations")
    p.add_argument("-o", "--output", metavar="DIR", help="autoware-design: the design folder written")
    p.add_argument("--force", action="store_true", help="autoware-design: overwrite files that exist")


def _timing(design: Any, ws: Any) -> int:
    """Decide ``design``'s monitoring fields against workspace ``ws``; print; the exit code."""
    from rclverify.model.nodl.design_timing import check_timing  # deferred: start-up (as in cmd_import)
    findings, decided = check_timing(design, ws.checked, ws.model.links)
    for d in decided:
        if d.status == "proved" and d.bound is not None:
            print(f"node {d.node}: {d.trigger}'s {d.field} holds: the contracts let it wait at most "
                  f"{float(d.bound.seconds) * 1000:g} ms <= {float(d.limit) * 1000:g} ms")
    for f in findings:
        for line in f.lines():
            print(line, file=sys.stderr)
    errors = sum(f.severity == "error" for f in findings)
    print(f"{len(design.nodes)} node(s), {len(design.wires)} wire(s); {len(decided)} monitoring field(s): "
          f"{sum(d.status == 'proved' for d in decided)} proved, {sum(d.status == 'refuted' for d in decided)} "
          f"refuted, {sum(d.status == 'undecided' for d in decided)} undecided; {errors} error(s), "
          f"{len(findings) - errors} warning(s)")
    return 1 if errors else 0


def _write(out: Path, texts: dict[str, str], force: bool) -> bool:
    """Write ``texts`` (by relative path) under ``out`` atomically; ``False`` after naming the files that
    exist when not ``force``."""
    from rclverify.core.atomic import atomic_write_text  # deferred: start-up (only when writing)
    there = [rel for rel in texts if (out / rel).exists()]
    if there and not force:
        for rel in there:
            print(f"{out / rel}: error: exists; nothing is overwritten unless --force", file=sys.stderr)
        return False
    for rel, text in texts.items():
        atomic_write_text(out / rel, text, within=out)
        print(out / rel)
    return True


def cmd_import(args: argparse.Namespace) -> int:
    """``rclverify import autoware-design`` (module docstring)."""
    from rclverify.model.nodl.design import read_design  # deferred: start-up (loads yaml and the design reader)
    from rclverify.model.nodl.design_write import workspace_texts  # deferred: start-up (as above)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads the workspace only when called)
    root = Path(args.design)
    if not root.is_dir():
        print(f"import autoware-design: error: {root}: no such folder", file=sys.stderr)
        return 2
    if args.check == bool(args.output):
        print("import autoware-design: error: give -o WS (write a workspace) or --check (decide against -w WS)",
              file=sys.stderr)
        return 2
    design = read_design(root, args.system)  # raises RclError, printed located by main
    if args.check:
        return _timing(design, Workspace(Path(args.workspace), args.plan))
    out = Path(args.output)
    folder = _inside(root, out)
    texts = workspace_texts(design, folder or "design")
    if folder is None:  # the design is copied into the workspace, which the plan's design key names
        from rclverify.model.nodl.design_read import design_files  # deferred: start-up (as above)
        for path, _shown in design_files(root):
            texts[f"design/{path.relative_to(root).as_posix()}"] = path.read_text(encoding="utf-8")
    plan = out / PLAN
    kept = plan.is_file()
    if kept:  # an existing plan is never replaced: its design key is set, the rest kept
        del texts[PLAN]
    if not (out / "dodo.py").exists():
        from rclverify.tools.scaffold import _env as scaffold_env  # deferred: start-up (the scaffold's templates)
        texts["dodo.py"] = scaffold_env().get_template("dodo.py.j2").render(name=design.name)
    if not _write(out, texts, args.force):
        return 1
    if kept:
        from rclverify.core.atomic import atomic_write_text  # deferred: start-up (only when writing)
        from rclverify.model.nodl.design_write import with_design_key  # deferred: start-up (as above)
        atomic_write_text(plan, with_design_key(plan.read_text(encoding="utf-8"), folder or "design"), within=out)
        print(f"{plan} (design: {folder or 'design'}; the plan's other content kept)")
    return _timing(design, Workspace(out, PLAN))


def _inside(design: Path, ws: Path) -> str | None:
    """``design``'s path relative to workspace ``ws`` (posix) when it lies inside it, else ``None``."""
    try:
        rel = design.resolve().relative_to(ws.resolve()).as_posix()
    except ValueError:
        return None
    return rel if rel != "." else None


def cmd_export_design(args: argparse.Namespace) -> int:
    """``rclverify export autoware-design -o DIR`` (module docstring)."""
    from rclverify.model.nodl.check import check  # deferred: start-up (loads jsonschema, yaml and more only when called)
    from rclverify.model.nodl.design_write import design_files  # deferred: start-up (as above)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads the workspace only when called)
    if not args.output:
        print("export autoware-design: error: give -o DIR, the design folder written", file=sys.stderr)
        return 2
    ws = Workspace(Path(args.workspace), args.plan)
    checked = ws.checked  # raises RclError, printed located by main
    docs = check(checked, ws.root).documents if (ws.root / "nodl").is_dir() else {}
    name = ws.plan.name or ws.root.resolve().name
    links = ws.plan.connections or ws.model.links  # the declared architecture, else what the model found
    return 0 if _write(Path(args.output), design_files(name, checked, links, docs), args.force) else 1


__all__ = ["FORMATS", "add_export_format", "add_import", "cmd_export_design", "cmd_import"]
