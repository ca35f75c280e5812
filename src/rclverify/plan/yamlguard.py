"""Bounds on the YAML the tool reads (the plan and the files it names).

PyYAML's composer keeps an alias as a second reference to the anchored node,
so a small file can describe an exponentially large document (the "billion
laughs" alias bomb), and an anchor may even refer to itself (a cycle).  The
plan loader turns the node graph into plain data, which would expand every
alias.  This module refuses such input before that happens:

``check_size(path, file)``      the file is at most :data:`MAX_YAML_BYTES`
                                bytes (checked with ``stat``, before reading);
``compose_guarded(text, file)`` ``yaml.compose`` with the safe loader, then an
                                iterative walk of the node graph that counts
                                the nodes the expansion would produce
                                (memoised per node, so the walk itself is
                                linear in the file) and refuses more than
                                :data:`MAX_YAML_NODES`, an alias cycle, or
                                nesting deeper than :data:`MAX_YAML_DEPTH`.

``safe_load_guarded(text, file)``  ``yaml.safe_load`` after the same checks: for
                                every other YAML file the plan names (review
                                records, summary statistics, trace mappings).

Every refusal is a :class:`~rclverify.plan.errors.PlanError` located in the
file (``E-yaml-limit``); memory stays bounded by the file size.  The limits
are far above any real plan (the case study's plan has a few hundred nodes);
docs/rcl-language.md records them.
"""
from __future__ import annotations

import os
from pathlib import Path

import yaml

from .errors import PlanError, plan_error

#: Largest plan file read, in bytes (1 MiB).
MAX_YAML_BYTES = 1 << 20
#: Largest number of YAML nodes after alias expansion.
MAX_YAML_NODES = 100_000
#: Deepest nesting of YAML collections.
MAX_YAML_DEPTH = 100


def check_size(path: Path, file: str) -> None:
    """Raise ``PlanError`` when ``path`` is larger than :data:`MAX_YAML_BYTES`
    (a missing file is left to the caller's read)."""
    try:
        size = os.stat(path).st_size
    except OSError:
        return
    if size > MAX_YAML_BYTES:
        raise plan_error(file, 1, 1, f"file is {size} bytes, above the limit of {MAX_YAML_BYTES} bytes for YAML input",
                         "E-yaml-limit")


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [x for kv in node.value for x in kv]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _refuse(file: str, node: yaml.Node, message: str) -> PlanError:
    mark = node.start_mark
    return plan_error(file, mark.line + 1, mark.column + 1, message, "E-yaml-limit")


def compose_guarded(text: str, file: str) -> yaml.Node | None:
    """``yaml.compose(text)`` with the limits of the module docstring.

    Returns the root node (``None`` for an empty document).  Raises
    ``yaml.YAMLError`` for malformed YAML (the caller locates it) and
    ``PlanError`` for input over a limit."""
    if len(text.encode("utf-8", "surrogatepass")) > MAX_YAML_BYTES:
        raise plan_error(file, 1, 1, f"YAML text above the limit of {MAX_YAML_BYTES} bytes", "E-yaml-limit")
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except RecursionError:
        raise plan_error(file, 1, 1, f"YAML nested too deeply (limit {MAX_YAML_DEPTH})", "E-yaml-limit") from None
    if root is None:
        return None
    size: dict[int, int] = {}
    on_path: set[int] = set()
    # Post-order walk with an explicit stack: (node, depth, children done?).
    stack: list[tuple[yaml.Node, int, bool]] = [(root, 1, False)]
    while stack:
        node, depth, done = stack.pop()
        key = id(node)
        if done:
            on_path.discard(key)
            total = 1 + sum(size[id(c)] for c in _children(node))
            if total > MAX_YAML_NODES:
                raise _refuse(file, node, f"YAML expands to more than {MAX_YAML_NODES} nodes through aliases "
                                          "(alias bomb?); refused")
            size[key] = total
            continue
        if key in size:
            continue
        if key in on_path:
            raise _refuse(file, node, "YAML alias refers to a node that contains it (a cycle); refused")
        if depth > MAX_YAML_DEPTH:
            raise _refuse(file, node, f"YAML nested too deeply (limit {MAX_YAML_DEPTH})")
        on_path.add(key)
        stack.append((node, depth, True))
        for c in reversed(_children(node)):
            if id(c) in on_path:
                raise _refuse(file, c, "YAML alias refers to a node that contains it (a cycle); refused")
            if id(c) not in size:
                stack.append((c, depth + 1, False))
    return root


def safe_load_guarded(text: str, file: str) -> object:
    """``yaml.safe_load(text)`` once :func:`compose_guarded` has accepted it.

    Raises ``yaml.YAMLError`` for malformed YAML and ``PlanError`` (located in
    ``file``) for input over a limit, before any alias is expanded."""
    if compose_guarded(text, file) is None:
        return None
    return yaml.safe_load(text)
