"""What a ``rclverify monitor`` run ends in, recorded or live (:mod:`.monitor`,
:mod:`.monitor_live`): the nodes ``--node`` selects, the items the run did
not judge printed one a line, and the exit code of a run with no violation
(``--strict``: 1 when an item went unjudged or a verdict stayed undecided).
"""
from __future__ import annotations

import argparse
import sys
from typing import Any, Mapping, Sequence

from rclverify.backends.monitors.judged import strict_line


def selected_nodes(checked: Any, names: Any, command: str) -> list[Any] | None:
    """The checked nodes ``names`` (``--node``) selects, every node when it
    is empty; ``None`` after printing one error line when a name is not a
    node of the contracts."""
    unknown = [n for n in names or () if n not in checked.nodes]
    if unknown:
        print(f"rclverify {command}: error: no node named {unknown[0]!r}; nodes: {', '.join(checked.nodes)}",
              file=sys.stderr)
        return None
    return [checked.nodes[n] for n in names] if names else list(checked.nodes.values())



def print_not_judged(items: list[dict[str, str]], prefix: str) -> None:
    """One line per item the run did not judge (silence is never green: judged.py)."""
    for i in items:
        print(f"{prefix}not judged: {i['kind']} {i['name']} ({i['node']}): {i['reason']}: {i['detail']}")



def strict_exit(args: argparse.Namespace, unjudged: list[dict[str, str]],
            undecided: Sequence[Mapping[str, object]] = ()) -> int:
    """The exit code of a run with no violation: 1 under ``--strict`` when
    an item went unjudged (``unjudged``, the first named on stderr) or a
    verdict stayed undecided (``undecided``: the ``inconclusive`` entries, as
    ``doit verify --strict`` fails on what is not discharged), else 0."""
    if not getattr(args, "strict", False) or not (unjudged or undecided):
        return 0
    if unjudged:
        print(strict_line(unjudged), file=sys.stderr)
    else:
        first = undecided[0]
        print(f"rclverify monitor: --strict: {len(undecided)} verdict(s) undecided; the first: {first['node']}: "
              f"{first['explanation']}", file=sys.stderr)
    return 1
