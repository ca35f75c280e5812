"""``rclverify import fret EXPORT.json``: FRET requirements brought into the workspace
(docs/requirements.md, "Requirements from FRET"; :mod:`rclverify.tools.fret.importer`)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any


def cmd_import_fret(args: argparse.Namespace) -> int:
    """Import the export, print what could not be imported and what changed, then check the plan
    with it.  Exit 1 on a malformed export or when the workspace no longer checks (the
    imported statements' types against the contracts); a requirement not imported is no error."""
    from rclverify.lang.errors import RclError  # deferred: start-up (imported where it is used)
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads the stages only when called)
    from rclverify.tools.fret.importer import import_fret, render  # deferred: start-up (loads jinja2 only when called)
    root = Path(args.workspace)
    res = import_fret(root, args.plan, Path(args.export), args.export)
    sys.stdout.write(render(res))
    try:
        Workspace(root, args.plan).checked  # the imported statements type-checked with the plan
    except RclError as exc:
        at = {i.requirement.loc.line: i for i in res.imported if i.requirement.formal is not None}
        for d in exc.diagnostics:
            i = at.get(d.loc.line) if d.loc.file == res.dest else None
            if i is None or i.requirement.formal is None:
                print(d, file=sys.stderr)
                continue
            # a column of the translated statement, not of the export: said so, at the reqid
            loc = i.requirement.loc
            print(f"{loc.file}:{loc.line}:{loc.col}: {d.severity}: {i.fret.reqid}: {d.message} (column "
                  f"{d.loc.col - loc.col + 1} of its translation: {i.requirement.formal.text})", file=sys.stderr)
        print(f"{args.export}: error: the plan does not check with the imported requirements (above)",
              file=sys.stderr)
        return 1
    return 0


def add_fret(group: Any) -> None:
    """Add ``fret`` to the subcommands ``group`` of ``rclverify import``."""
    f = group.add_parser("fret", help="a FRET export (JSON): each requirement into the plan by its reqid",
                         description="import a FRET export (JSON): each requirement becomes a requirement of the "
                                     "plan, keyed by its reqid; a re-import updates them")
    f.add_argument("export", help="the FRET export (FRET: Export, requirements and variables, JSON)")
    f.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
    f.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    f.set_defaults(fn=cmd_import_fret)
