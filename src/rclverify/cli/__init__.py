"""cli (its place among the layers: docs/architecture.md): the ``rclverify`` command, parsing and printing only.

``commands`` (the commands' table and the entry point), one module per
command group: ``contracts`` (check, latex, fmt), ``calculus`` (graph,
compose, health, export, quotient, refines), ``requirements`` (with
deadlines), ``verify`` (with report), ``explain`` (with status),
``workspace`` (init, cache, review), ``bundle``, ``runs`` (monitor and
oracle's parsers; ``monitor`` runs them), ``ros``, ``generate``, ``lsp``;
``common`` holds what they share.  Imports every layer below.
"""
from __future__ import annotations


def main(argv: list[str] | None = None) -> int:
    """The ``rclverify`` command's entry point (pyproject's ``rclverify.cli:main``):
    :func:`rclverify.cli.commands.main`, imported when called so that
    importing a command group does not load every command."""
    from rclverify.cli.commands import main as run  # deferred: start-up (loads rclverify.cli.bundle, rclverify.cli.calculus and more only when called)
    return run(argv)
