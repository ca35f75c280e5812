"""An edit inside one node's clauses, checked without reading the system again.

A repair candidate (:mod:`.recheck`) is the workspace's contracts with one
edit.  Parsing every contract file again and type-checking the whole
system for each candidate made the diagnosis quadratic in the system: on a
chain of N nodes whose side conditions all fail there are O(N) candidates,
each O(N) to parse and check (0.2 s at 10 nodes, 101.6 s at 200).

When the edit lies inside one node's text and leaves that node's interface
as it was, the system the full path would build differs from the checked
one in that node's clauses only:

* the node's text with the edit made is parsed alone, at its place in the
  file (the lines and columns before it are padded, so every location in
  it is the one a parse of the whole edited file gives);
* it must be one node of the same name, inputs, outputs, topics and
  service links (AST equality, locations aside); otherwise the full path
  decides;
* it is type-checked alone against the system's contexts
  (:func:`rclverify.lang.typecheck.check_node_again`): type checking a node
  reads the contexts and that node only;
* the system model is the workspace's own: links, environment inputs and
  loops are made from interfaces, topics and service links, which the edit
  did not change (:func:`rclverify.model.system.model.build`).

The other nodes are the checked ones, with their locations as they were:
an edit that adds a line moves the nodes after it in the file, but nothing
the repair checks read of another node depends on where it is written
(they read statuses, models and cores of Z3 queries over the formulas).

Anything else (an edit across nodes or in a context, a changed interface,
text that does not parse alone, a unit where the system had none) is
:data:`FULL`: the caller parses and checks the whole edited system as
before.  Errors of the edited node itself are the full path's errors too
(``None``: the candidate does not check).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any

from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check_node_again
from rclverify.lang.types import Checked
from rclverify.model.system.model import SystemModel
from rclverify.diagnosis.edits import Edit

#: Returned when the edit is not inside one node's clauses: check the whole edited system.
FULL = object()


def _offset(lines: list[str], line: int, col: int) -> int:
    return sum(len(x) for x in lines[:line - 1]) + col - 1


def _host(checked: Checked, edit: Edit, lines: list[str]) -> tuple[ast.Spec, ast.Node, int, int] | None:
    """The spec and node of ``edit.file`` whose text holds the whole edit,
    with the node's start and end offsets in the file; ``None`` when none does."""
    a = _offset(lines, edit.line, edit.col)
    b = _offset(lines, edit.end_line, edit.end_col)
    for spec in checked.specs:
        if spec.file != edit.file:
            continue
        for n in spec.nodes:
            loc = n.loc
            if loc.file != edit.file or not loc.end_line:
                continue
            start, end = _offset(lines, loc.line, loc.col), _offset(lines, loc.end_line, loc.end_col)
            if start < a and b < end:  # strictly inside: the header and the closing brace are not edited
                return spec, n, start, end
    return None


def _same_interface(a: ast.Node, b: ast.Node) -> bool:
    return (a.name, a.inputs, a.outputs, a.topics, a.links) == (b.name, b.inputs, b.outputs, b.topics, b.links)


def spliced_system(ws: Any, edit: Edit, source: str) -> tuple[Checked, SystemModel] | None | object:
    """The workspace's checked system and model with ``edit`` made to the
    node whose clauses it lies in (module docstring).  ``source`` is the
    text of ``edit.file``.  Returns the pair; ``None`` when the edited node
    does not type-check (as the full path would answer); :data:`FULL` when
    this shortcut does not apply."""
    checked: Checked = ws.checked
    lines = source.splitlines(keepends=True)
    host = _host(checked, edit, lines)
    if host is None:
        return FULL
    spec, old, start, end = host
    new_source = edit.apply(source)
    new_end = end + len(new_source) - len(source)
    loc = old.loc
    # padded so the node's locations are those of the whole edited file (nothing before it changed)
    padded = "\n" * (loc.line - 1) + " " * (loc.col - 1) + new_source[start:new_end]
    try:
        piece = parse_text(padded, edit.file)
    except RclError:
        return FULL  # decided on the whole file (an edit text is RCL, but let the full path say so)
    if piece.contexts or len(piece.nodes) != 1 or not _same_interface(piece.nodes[0], old):
        return FULL
    new = piece.nodes[0]
    had_units = any(getattr(s, "has_units", True) for s in checked.specs)
    if piece.has_units and not had_units:
        return FULL  # the unit pass would now run for the whole system
    new_spec = replace(spec, nodes=tuple(new if n is old else n for n in spec.nodes),
                       has_units=spec.has_units or piece.has_units)
    specs = tuple(new_spec if s is spec else s for s in checked.specs)
    try:
        cn = check_node_again(specs, new)
    except RclError:
        return None
    nodes = {name: (cn if name == old.name else c) for name, c in checked.nodes.items()}
    return Checked(checked.env, nodes, specs), ws.model
