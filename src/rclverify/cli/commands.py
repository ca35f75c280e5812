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
``rclverify repair ID [--apply]``  a problem's checked repairs; --apply writes one and checks again
``rclverify refines A.rcl:N B.rcl:M``  may contract M replace contract N?
``rclverify quotient NODE [-o FILE]``  the weakest contract of NODE its neighbours need
``rclverify init DIR [--nodes A,B]``  write a new workspace that verifies at once
``rclverify bundle [-o FILE]``     the assessor's bundle; ``--verify FILE`` checks one
``rclverify review NODE [-o FILE]``  write a review record to fill in
``rclverify ros scan PATH...``     the ROS computation graph from workspaces (docs/ros.md)
``rclverify ros check``            the plan's contracts against that graph
``rclverify nodl check``           the NoDL documents against the contracts (docs/nodl.md)
``rclverify import autoware-design DIR -o WS``  an Autoware System Designer design as a workspace (docs/nodl.md)
``rclverify lsp``                  the RCL language server over stdio (docs/editor.md)

Exit codes: 0 success, 1 errors in the input (or, for ``compose``/``verify
--strict``, an obligation that does not hold), 2 usage errors.  A user's
mistake prints ``file:line:col: error: message`` lines, never a traceback.

This module holds :func:`main` and the table of commands
(:data:`COMMANDS`); each command group is a module of its own beside it,
parsing and printing only, imported only when one of its commands runs
(or when the help lists them all): ``rclverify monitor`` loads the
parsers and modules of ``monitor`` alone (docs/scale.md, "Start-up").
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys
from pathlib import Path
from typing import Any, Callable, Sequence, cast

from rclverify.cli.common import AddCommand, print_diags
from rclverify.core.extras import MissingExtra
from rclverify.lang.errors import RclError

#: One entry of the command table: the command group's module under ``rclverify.cli``, the function of it
#: that adds the parsers, and the commands that function adds.
Entry = tuple[str, str, tuple[str, ...]]

#: The commands, in the order ``rclverify --help`` lists them: each function adds its command's parser
#: (or a group's) with ``add(name, fn, help, workspace)`` (:func:`main`).
COMMANDS: tuple[Entry, ...] = (
    ("contracts", "add_check", ("check",)), ("contracts", "add_latex_fmt", ("latex", "fmt")),
    ("calculus", "add_graph_to_export", ("graph", "compose", "health", "export")), ("verify", "add_report", ("report",)),
    ("requirements", "add_requirements_deadlines", ("requirements", "deadlines")), ("workspace", "add_cache", ("cache",)),
    ("explain", "add_status_explain", ("status", "explain")), ("repair", "add_repair", ("repair",)),
    ("verify", "add_verify", ("verify",)), ("workspace", "add_init", ("init",)), ("bundle", "add_bundle", ("bundle",)),
    ("workspace", "add_review", ("review",)), ("calculus", "add_quotient_refines", ("quotient", "refines")),
    ("standards", "add_standards", ("standards",)),
)
#: The commands with subcommands of their own (``ros``, ``nodl``, ``generate``, ``import``), and ``lsp``: each
#: function adds to the subparsers.
SUBCOMMAND_GROUPS: tuple[Entry, ...] = (
    ("ros", "add_parsers", ("ros",)), ("nodl", "add_parsers", ("nodl",)), ("generate", "add_parsers", ("generate",)),
    ("design", "add_import", ("import",)), ("lsp", "add_parsers", ("lsp",)),
)
#: Listed after them: monitoring recorded and live runs (docs/monitors.md).
LAST_COMMANDS: tuple[Entry, ...] = (("runs", "add_monitor", ("monitor",)), ("runs", "add_oracle", ("oracle",)))
#: Every command's name, in the table's order.
NAMES = tuple(name for _, _, names in COMMANDS + SUBCOMMAND_GROUPS + LAST_COMMANDS for name in names)


def _adder(entry: Entry) -> Callable[[Any], None]:
    """The function of ``entry`` (:data:`COMMANDS`), its module imported now."""
    module, function, _ = entry
    return cast("Callable[[Any], None]", getattr(importlib.import_module(f"rclverify.cli.{module}"), function))


def chosen(argv: Sequence[str]) -> str | None:
    """The command ``argv`` (the arguments after the program's name) runs when its first argument
    names one, else ``None`` (``--help``, ``--version``, nothing, a mistake): then every command's
    parser is made, so that the help and argparse's errors list them all."""
    return argv[0] if argv and argv[0] in NAMES else None


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
    from rclverify import __version__  # deferred: start-up (imported where it is used)
    p.add_argument("--version", action="version", version=f"rclverify {__version__}")
    argv = list(sys.argv[1:] if argv is None else argv)
    name = chosen(argv)  # only the command run has its parser made, and its module imported (start-up)
    # with one command's parser, the usage still names every command, as argparse writes them all
    sub = p.add_subparsers(dest="command", required=True,
                           **({"metavar": "{" + ",".join(NAMES) + "}"} if name is not None else {}))

    def add(name: str, fn: Callable[[argparse.Namespace], int], help: str, workspace: bool = False) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help, description=help)
        sp.set_defaults(fn=fn)
        if workspace:
            sp.add_argument("-w", "--workspace", default=".", help="workspace root (default: .)")
            sp.add_argument("--plan", default="contracts/plan.yaml", help="plan file, relative to the workspace")
        return sp

    for entries, target in ((COMMANDS, add), (SUBCOMMAND_GROUPS, sub), (LAST_COMMANDS, add)):
        for entry in entries:
            if name is None or name in entry[2]:
                _adder(entry)(target)
    args = p.parse_args(argv)
    return _run(args)


def _run(args: argparse.Namespace) -> int:
    """Run the command ``args`` chose; every fault of the user or the machine is one plain line."""
    from rclverify.core.runlock import RunInProgress  # deferred: start-up (loads rclverify.core, rclverify.core.runlock only when called)
    try:
        code = int(args.fn(args))
        if not sys.stdout.closed:  # the language server closes its stdout at `exit`
            sys.stdout.flush()  # a closed pipe shows here, not at exit, where it could not be caught
        return code
    except BrokenPipeError:  # `rclverify explain ID | head`: the reader left; end quietly
        return _reader_left()
    except RclError as exc:
        return print_diags(exc)
    except MissingExtra as exc:  # an optional part not installed: one line naming the extra (core/extras.py)
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except RunInProgress as exc:  # report/bundle --no-wait while a run holds the workspace
        print(f"{args.workspace}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
    except OSError as exc:  # a fault of the machine (read-only directory, full disk): one plain line
        from rclverify.core.faults import describe_os_error  # deferred: optional or conditional (inside a block)
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
