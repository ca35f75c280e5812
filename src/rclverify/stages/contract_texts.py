"""Texts made from each contract file's syntax tree, kept between runs.

Every node of the system is printed by the check stage (and by the report
for what the check stage did not keep): its RCL text (the snapshot), the RCL text of each assumption and
guarantee, its LaTeX, and each file's lint warnings.  For a 1000-node
system that was 0.2 s of the check task and 0.2-0.3 s of each report task
after a one-contract edit (docs/scale.md, "What is kept between runs"), although only the
edited file's texts can differ.  They are pure functions of a file's text,
so they are kept in ``artifacts/cache/contract-texts.pickle``, a
:class:`~rclverify.core.cache.store.Shelf` of kind ``contract-texts``, per
contract file, keyed by the file's name and the sha256 of the text that was
parsed (``Workspace.parsed``; the kind's salt holds the rclverify code: a
changed printer misses).

The check task (:func:`rclverify.app.pipeline.stage_check`) fills and writes the
file; the report tasks, which run after it, only read it and make what it
lacks.  A damaged, missing or foreign file is an empty cache; the texts are
the same with or without it (``tests/stages/test_contract_texts.py``).
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (the TypedDicts below).
from pathlib import Path
from typing import TYPE_CHECKING, Any, NotRequired, TypedDict

from rclverify.core.cache import Shelf
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl, to_rcl, type_to_rcl, unit_to_rcl

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace

CACHE = "artifacts/cache/contract-texts.pickle"


class NodeTexts(TypedDict):
    """The texts of one node (stages/contract_texts.py ``node_texts``): its RCL and LaTeX, its ports as
    ``[name, type with unit]`` and its assumptions and guarantees as ``[formula, "file:line:col"]``."""
    rcl: str
    latex: str
    inputs: list[list[str]]
    outputs: list[list[str]]
    assumptions: list[list[str]]
    guarantees: list[list[str]]


class FileTexts(TypedDict):
    """One contract file's kept texts: node name -> :class:`NodeTexts`, and its lint warnings' JSON once made."""
    nodes: dict[str, NodeTexts]
    lint: NotRequired[list[dict[str, Any]]]


def node_texts(node: ast.Node) -> NodeTexts:
    """The texts of one node: ``{"rcl": the node as RCL (the snapshot's
    text), "latex": its LaTeX block (:func:`rclverify.lang.latex.node_latex`:
    no preamble, its real file name), "inputs"/"outputs": [[name, type as RCL with its unit, ``REAL [m]``],
    ...], "assumptions"/"guarantees": [[formula as RCL, "file:line:col"],
    ...]}`` (lists, in declaration order)."""
    from rclverify.lang.latex import node_latex  # deferred: start-up (loads jinja2, rclverify.lang.latex and more only when called)
    return {
        "rcl": to_rcl(ast.Spec((), (node,))), "latex": node_latex(node),
        "inputs": [[v.name, type_to_rcl(v.type) + unit_to_rcl(v.unit)] for v in node.inputs],
        "outputs": [[v.name, type_to_rcl(v.type) + unit_to_rcl(v.unit)] for v in node.outputs],
        "assumptions": [[expr_to_rcl(a.formula), str(a.loc)] for a in node.assumes],
        "guarantees": [[expr_to_rcl(g.formula), str(g.loc)] for g in node.guarantees],
    }


def lint_json(spec: ast.Spec) -> list[dict[str, Any]]:
    """The lint warnings of one parsed file (:func:`rclverify.lang.lint.lint`) as JSON."""
    from rclverify.lang.lint import lint  # deferred: start-up (loads rclverify.lang.errors, rclverify.lang.lint and more only when called)
    return [d.to_json() for d in lint(spec)]


class ContractTexts:
    """The texts of the contract files of ``ws`` (whose contracts check:
    ``ws.checked`` is read), from the cache file when it has them.

    :meth:`node` and :meth:`lint` make what the cache lacks; :meth:`save`
    writes the texts of the workspace's current files when anything was
    made.  Never raises for a bad cache file.
    """

    def __init__(self, ws: "Workspace") -> None:
        self.ws = ws
        ws.checked  # fills ws.parsed with the sha256 of each file's parsed text
        self.path: Path = ws.path(CACHE)
        self._shelf = Shelf(self.path, "contract-texts")
        self._files: dict[str, FileTexts] = {}
        for rel, (sha, _) in ws.parsed.items():
            self._files[rel] = self._shelf.get_or_make(self._shelf.key("file", rel, sha), lambda: {"nodes": {}})

    def _entry(self, rel: str) -> FileTexts:
        entry = self._files.get(rel)
        if entry is None:  # not a parsed file of the workspace: kept for this object only
            entry = self._files[rel] = {"nodes": {}}
        return entry

    def node(self, node: ast.Node) -> NodeTexts:
        """:func:`node_texts` of ``node`` (a node of ``ws.checked``)."""
        got: NodeTexts | None = self._entry(node.loc.file)["nodes"].get(node.name)
        if got is None:
            got = self._entry(node.loc.file)["nodes"][node.name] = node_texts(node)
            self._shelf.changed()
        return got

    def lint(self, spec: ast.Spec) -> list[dict[str, Any]]:
        """:func:`lint_json` of ``spec`` (a file of ``ws.checked``)."""
        entry = self._entry(spec.file)
        got: list[dict[str, Any]] | None = entry.get("lint")
        if got is None:
            got = entry["lint"] = lint_json(spec)
            self._shelf.changed()
        return got

    def save(self) -> bool:
        """Write the texts of the workspace's parsed files atomically when
        any were made (those of files no longer parsed are dropped).
        Returns whether the file was written; raises ``OSError`` when the
        cache directory cannot be written."""
        return self._shelf.save()
