"""What the ``rclverify`` commands share: option types, the workspace of a command, located errors,
writing a command's output, the workspace's run lock.

Parsing and printing only; what a command computes lives in the layers
below (stages, report, calculus).  A command group's module is imported
when one of its commands runs (and every one for ``rclverify --help``),
and each imports the layers below inside the function that needs them: a
command pays only for its own imports (docs/scale.md, start-up).
"""
from __future__ import annotations

import argparse
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator

from rclverify.lang.errors import RclError

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace

#: ``add(name, fn, help, workspace=False)``: a subcommand's parser (:func:`rclverify.cli.commands.main`).
AddCommand = Callable[..., argparse.ArgumentParser]


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


def print_diags(exc: RclError) -> int:
    """Print each located diagnostic of ``exc`` on standard error; exit code 1."""
    for d in exc.diagnostics:
        print(d, file=sys.stderr)
    return 1


def emit(text: str, output: str | None) -> int:
    """Write ``text`` to stdout, or atomically to the file ``output``
    (``-o FILE``; a write error is a located ``E-io`` error, exit 1)."""
    if output is None:
        print(text, end="")
        return 0
    from rclverify.lang.output import write_atomic  # deferred: start-up (loads rclverify.lang.ast, rclverify.lang.output and more only when called)
    write_atomic(Path(output), text)
    return 0


def workspace_of(args: argparse.Namespace) -> Workspace:
    """The :class:`~rclverify.stages.workspace.Workspace` of ``args.workspace`` and ``args.plan``."""
    from rclverify.stages.workspace import Workspace  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    return Workspace(Path(args.workspace), args.plan)


def io_error(path: Path, message: str) -> Any:
    """A located ``E-io`` diagnostic at line 1 of ``path``."""
    from rclverify.lang.ast import Loc  # deferred: start-up (loads rclverify.lang.ast, fractions only when called)
    from rclverify.lang.errors import error  # deferred: start-up (imported where it is used)
    return error(Loc(str(path), 1, 1), message, "E-io")


@contextmanager
def run_lock(args: argparse.Namespace) -> Iterator[None]:
    """Hold the workspace's run lock (:mod:`rclverify.core.runlock`) for the block:
    a command that writes ``reports/`` or reads the evidence as a whole
    (``report``, ``bundle``) waits for a ``doit verify`` in progress, which
    would otherwise rewrite them under it.  ``--no-wait``/``RCLVERIFY_NO_WAIT=1``
    make it exit 1 instead (:class:`~rclverify.core.runlock.RunInProgress`,
    printed by :func:`main`).  Released at the end of the block; a lock this
    process already held stays held."""
    from rclverify.core import runlock  # deferred: start-up (imported where it is used)
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


def no_wait_option(sp: argparse.ArgumentParser) -> None:
    """``--no-wait`` of a command that waits for a run in progress (``report``, ``bundle``)."""
    sp.add_argument("--no-wait", action="store_true",
                    help="exit 1 instead of waiting when a run is in progress in the workspace "
                         "(also: RCLVERIFY_NO_WAIT=1)")
