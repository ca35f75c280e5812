"""``rclverify lsp``: the RCL language server over stdio (docs/editor.md).

Exit codes: 0 when the client ends the session; 2 usage errors (also a
``-w`` that names no directory).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any


def add_parsers(sub: Any) -> None:
    """Add the ``lsp`` command to ``rclverify``'s parser (``sub``: its subparsers)."""
    p = sub.add_parser("lsp", help="the RCL language server over stdio (docs/editor.md)",
                       description="the RCL language server over stdio: diagnostics as you type, hover, "
                                   "definitions, references, the repairs Z3 checked as quick fixes, formatting "
                                   "and completion (docs/editor.md)")
    p.add_argument("-w", "--workspace", default=None,
                   help="workspace root when the editor names none (default: the editor's folder, else .)")
    p.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
    p.add_argument("--stdio", action="store_true", help="talk over stdin and stdout (the only transport; "
                   "accepted because editors pass it)")
    p.set_defaults(fn=cmd_lsp)


def cmd_lsp(args: argparse.Namespace) -> int:
    """Serve the workspace until the client exits; exit 2 (one line) when
    ``-w`` names no directory."""
    if args.workspace and not Path(args.workspace).is_dir():
        print(f"{args.workspace}: error: no such workspace directory", file=sys.stderr)
        return 2
    from rclverify.core.extras import require  # deferred: start-up (only for this command)
    require("pygls", "the RCL language server")  # MissingExtra: one line (cli/commands.py)
    require("lsprotocol", "the RCL language server")
    from rclverify.tools.lsp.server import serve  # deferred: start-up (loads lsprotocol, pygls and more only when called)
    return serve(Path(args.workspace) if args.workspace else None, args.plan)
