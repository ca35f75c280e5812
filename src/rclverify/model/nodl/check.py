"""A workspace's NoDL documents checked against its contracts and against each other (docs/nodl.md).

The documents are the files ``*.nodl.yaml``, ``*.nodl.yml`` and
``*.nodl.json`` of one folder (``nodl/`` beside ``contracts/`` unless told
otherwise); a document named after a contract's node (``nodl/ScanGuard.nodl.yaml``
for ``node ScanGuard``) is that node's interface.  :func:`check` reads them
all (:mod:`.document`), then finds

* per node with a document: its contract's endpoints against the document's
  (:func:`.contract.compare`: ``nodl-missing``, ``nodl-extra``, ``nodl-type``);
* per topic, service and action two documents share (the nodes' and those
  named after no node that no document includes, each in the root
  namespace): the types they give it (``nodl-connect-type``) and, for a
  topic's publisher and subscriber and a service's server and client,
  whether the QoS the writer offers meets what the reader requests
  (``nodl-qos``; :func:`.sets.connections`);
* per parameter: its default against its declared constraints, and the
  contracts' constant of the same name against them (``nodl-parameter``,
  :mod:`.params`); and, where it sets an input of the node's contract,
  whether its constraints ensure what the contract assumes of that input
  (Z3; ``nodl-parameter-assume``, :mod:`.param_assume`);
* a document named after no node that no other document includes
  (``nodl-node``, a warning: a part meant for ``include`` is fine).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Iterable, Sequence

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError
from rclverify.lang.types import Checked
from rclverify.model.nodl.contract import compare
from rclverify.model.nodl.document import SUFFIXES, Document, Resolver, read_document
from rclverify.model.nodl.findings import Finding
from rclverify.model.nodl.param_assume import Side, check_parameters
from rclverify.model.nodl.params import broken
from rclverify.model.nodl.sets import Member, connections

#: The folder of a workspace's NoDL documents, relative to its root.
FOLDER = "nodl"


@dataclass
class Result:
    """What :func:`check` read and found: ``documents`` by node (the nodes of the contracts that
    have one), ``parts`` (documents named after no node), ``findings`` in file order."""

    documents: dict[str, Document] = field(default_factory=dict)
    parts: list[Document] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)
    #: the side conditions of parameters that set an input (:mod:`.param_assume`), each decided
    sides: list[Side] = field(default_factory=list)

    @property
    def errors(self) -> int:
        """How many findings are errors."""
        return sum(f.severity == "error" for f in self.findings)


def document_files(folder: Path) -> list[Path]:
    """The NoDL documents of ``folder`` (not of its sub-folders), sorted by name; none when it
    does not exist."""
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.is_file() and p.name.endswith(SUFFIXES))


def shown(root: Path) -> "_Display":
    """The names diagnostics give files: relative to ``root`` when inside it."""
    return _Display(root.resolve())


class _Display:
    def __init__(self, root: Path) -> None:
        self.root = root

    def __call__(self, path: Path) -> str:
        try:
            return path.resolve().relative_to(self.root).as_posix()
        except ValueError:
            return str(path)


def read_all(files: Iterable[Path], resolver: Resolver) -> list[Document]:
    """Every document of ``files``, read; raises one :class:`RclError` with the diagnostics of all
    the files that could not be read (each located)."""
    docs: list[Document] = []
    diags: list[Diagnostic] = []
    for path in files:
        try:
            docs.append(read_document(path, resolver.display(path), resolver))
        except RclError as exc:
            diags.extend(exc.diagnostics)
    if diags:
        raise RclError(diags)
    return docs


def _constant_value(expr: ast.Expr) -> Fraction | None:
    """The number a constant's definition writes (``2.5``, ``-1``), ``None`` for anything else."""
    if isinstance(expr, ast.NumLit):
        return expr.value
    if isinstance(expr, ast.Unary) and expr.op == "-" and isinstance(expr.operand, ast.NumLit):
        return -expr.operand.value
    return None


def _parameters(documents: Sequence[tuple[str, Document]], checked: Checked) -> list[Finding]:
    """Each parameter's default and the contracts' constant of its name against its constraints."""
    out: list[Finding] = []
    for node, doc in documents:
        for p in doc.parameters:
            if p.has_default:
                bad = broken(p.validation, p.default)
                if bad:
                    out.append(Finding("nodl-parameter", f"node {node}: parameter {p.name}'s default {p.default!r} "
                                                         f"is not {' and '.join(bad)}, as its declaration requires",
                                       (p.default_loc, p.loc)))
            const = checked.env.constants.get(p.name) or checked.env.constants.get(p.name.rsplit(".", 1)[-1])
            value = _constant_value(const[1]) if const else None
            if const is None or value is None:
                continue
            number: float | int = int(value) if value.denominator == 1 else float(value)
            bad = broken(p.validation, number)
            if bad:
                out.append(Finding("nodl-parameter", f"the contracts' constant {p.name.rsplit('.', 1)[-1]} = {number} "
                                                     f"is not {' and '.join(bad)}, which node {node}'s NoDL document "
                                                     f"declares of its parameter {p.name}", (const[1].loc, p.loc)))
    return out


def check(checked: Checked, root: Path, folder: Path | None = None, prefixes: Sequence[Path] = ()) -> Result:
    """Read the NoDL documents of ``folder`` (default ``root/nodl``) and check them against the
    contracts ``checked`` and each other (module docstring).  ``prefixes``: install prefixes whose
    ament index resolves ``nodl://`` includes.  A document read must lie inside ``root`` or
    ``folder`` (a ``local://`` include or a link leading elsewhere is a located error:
    :class:`~rclverify.model.nodl.document.Resolver`).  Raises :class:`RclError` (located) when a
    document cannot be read (not JSON or YAML, against the schema, an include not resolved or
    cycling); returns the findings otherwise."""
    display = shown(root)
    resolver = Resolver(prefixes, display, (root,) + ((folder,) if folder is not None else ()))
    docs = read_all(document_files(folder or root / FOLDER), resolver)
    res = Result()
    included = {f for d in docs for f in d.files[1:]}
    for doc in docs:
        cn = checked.nodes.get(doc.node)
        if cn is not None:
            res.documents[doc.node] = doc
            res.findings += compare(cn, doc)
            sides, found = check_parameters(cn, doc, checked)
            res.sides += sides
            res.findings += found
        else:
            res.parts.append(doc)
            if doc.file not in included:
                res.findings.append(Finding("nodl-node", f"NoDL document {doc.file} is named after {doc.node!r}, and no "
                                                         "contract declares that node (nor does another document "
                                                         "include it)", (ast.Loc(doc.file, 1, 1),), "warning"))
    nodes = [Member(n, "/", d) for n, d in sorted(res.documents.items())]
    res.findings += connections(nodes + [Member(d.node, "/", d) for d in res.parts if d.file not in included])
    res.findings += _parameters(sorted(res.documents.items()), checked)
    res.findings.sort(key=lambda f: (f.locs[0].file, f.locs[0].line, f.locs[0].col, f.code))
    return res


__all__ = ["FOLDER", "Result", "check", "document_files", "read_all", "shown"]
