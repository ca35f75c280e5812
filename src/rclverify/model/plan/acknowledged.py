"""Acknowledged warnings: a lint or health warning answered in the plan.

A warning (a lint warning of ``rclverify check``, a contract health finding
of status ``warning`` such as a redundant conjunct) may be acknowledged in
``contracts/plan.yaml`` with a reason::

    acknowledged:
      - warning: Mover.g2.c1.redundant          # a health finding's id, or a lint code
        text: "out.arrived -> out.progress >= 0"  # the flagged text (or sha256: its digest)
        reason: kept for the reader of the action's contract

An acknowledgement answers one finding: its file, its node and its text.  A
health finding's id names its node (and so its file); a lint code is raised
wherever the same slip is written, so a lint acknowledgement names the
contract ``file:`` of its finding, and ``node:`` when that file holds more
than one node (:func:`read_acknowledgements`, :func:`check_acknowledgements`:
one written wider is a located plan error).  A finding of another file or
node is never accepted by it.

The acknowledgement is bound to the *flagged text* (:func:`flagged_text`:
the conjunct, guarantee or clause the warning is about), as a review answer
is bound to its ``conjunct:`` text (docs/integrity.md): when that text
changes, the warning is raised again and the acknowledgement is reported
stale.  An acknowledgement that matches no warning is reported stale too,
and one naming an error or a problem is refused (only warnings can be
accepted as a risk).  ``--strict`` fails on unacknowledged warnings and on
stale acknowledgements; an acknowledged warning is shown in every output
with its reason (SARIF: a ``suppressions`` entry with the justification).
Format and decisions: docs/plan.md, "Acknowledged warnings".
"""
from __future__ import annotations

import hashlib
import posixpath
import re
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

import msgspec

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, error
from rclverify.lang.types import Checked
from rclverify.model.plan.document import PlanDocument
from rclverify.model.plan.errors import plan_error
from rclverify.lang.printer import to_rcl, expr_to_rcl
from rclverify.records.findings import Acknowledged, FindingRow
from rclverify.records.lint_rows import AcknowledgementRow, LintRow
from rclverify.records.statuses import AcknowledgementStatus

#: ``<Node>.g<k>[.c<j>].<check>`` or ``<Node>.<check>``: a health finding's id (calculus/health/finding.py).
_HEALTH_ID = re.compile(r"^(?P<node>[A-Za-z_][A-Za-z0-9_]*)(?:\.g(?P<k>\d+)(?:\.c(?P<j>\d+))?)?\.(?P<check>[A-Za-z0-9_-]+)$")


@dataclass(frozen=True)
class Acknowledgement:
    """One ``acknowledged:`` entry of the plan.

    ``warning`` is a health finding's id (``Mover.g2.c1.redundant``) or a
    lint code (``W-unused-bound``, with the contract ``file`` of its finding
    and, in a file of several nodes, the ``node`` whose span holds it);
    ``text`` the flagged text as written, ``sha256`` its digest (hex, a
    prefix of at least 12 digits; one of the two is given); ``reason`` the
    user's justification; ``loc`` the entry's place in the plan."""

    warning: str
    reason: str
    loc: ast.Loc
    text: str | None = None
    sha256: str | None = None
    file: str | None = None
    node: str | None = None

    def binds(self, flagged: str) -> bool:
        """Is this acknowledgement bound to ``flagged`` (the finding's flagged text now)?"""
        if self.text is not None:
            return normal(self.text) == normal(flagged)
        return bool(self.sha256) and digest(flagged).startswith(str(self.sha256).lower())


def normal(text: str) -> str:
    """``text`` with its white space runs made one space (the form digested)."""
    return " ".join(str(text).split())


def digest(text: str) -> str:
    """The sha256 (hex) of :func:`normal` ``text``: what an acknowledgement binds."""
    return hashlib.sha256(normal(text).encode("utf-8")).hexdigest()


def health_node(warning: str) -> str | None:
    """The node a health finding's id ``warning`` names (``Mover`` of
    ``Mover.g2.c1.redundant``); ``None`` for a lint code (``W-unused-bound``)."""
    m = _HEALTH_ID.match(warning)
    return m["node"] if m else None


def read_acknowledgements(doc: PlanDocument, locs: Mapping[Any, ast.Loc], plan_rel: str) -> tuple[Acknowledgement, ...]:
    """The plan's ``acknowledged:`` entries (``doc``: the plan's typed sections; each has
    ``warning`` and ``reason``).  Raises :class:`~.errors.PlanError`, located
    at the entry, for an entry that gives neither or both of ``text`` and
    ``sha256``, a lint code without ``file:`` (it would answer the same
    warning in every file), a ``node:`` other than the node a health id
    names, or a reason that is no sentence (fewer than three words of
    letters: ``reason: "..."`` says nothing a reviewer can weigh).  Rule:
    docs/plan.md, "Acknowledged warnings"."""
    out = []
    for i, a in enumerate(doc.acknowledged):
        at = locs.get(("acknowledged", i), ast.Loc(plan_rel, 1, 1))
        if (a.text is None) == (a.sha256 is None):
            raise plan_error(plan_rel, at.line, at.col, f"acknowledged[{i}] ({a.warning}): give the flagged text "
                             "it accepts as text: or its digest as sha256: (one of the two; the report shows both "
                             "for every warning)", "E-acknowledged")
        if len(re.findall(r"[A-Za-z]{2,}", a.reason)) < 3:
            r = locs.get(("acknowledged", i, "reason"), at)
            raise plan_error(plan_rel, r.line, r.col, f"acknowledged[{i}] ({a.warning}): the reason must say why "
                             f"the warning is accepted, in words a reviewer can weigh, not {a.reason!r}",
                             "E-acknowledged")
        owner = health_node(a.warning)
        if owner is None and a.file is None:
            raise plan_error(plan_rel, at.line, at.col, f"acknowledged[{i}] ({a.warning}): a lint code is raised "
                             "wherever the same text is written, so this would answer it in every file; give the "
                             "contract file of the one warning it answers as file: (and node: when that file holds "
                             "more than one node)", "E-acknowledged")
        if owner is not None and a.node is not None and a.node != owner:
            n = locs.get(("acknowledged", i, "node"), at)
            raise plan_error(plan_rel, n.line, n.col, f"acknowledged[{i}] ({a.warning}): node: {a.node} is not "
                             f"the node the finding's id names ({owner})", "E-acknowledged")
        out.append(Acknowledgement(a.warning, normal(a.reason), locs.get(("acknowledged", i), ast.Loc(plan_rel, 1, 1)),
                                   a.text, a.sha256, a.file, a.node))
    return tuple(out)


def _path(file: str) -> str:
    """``file`` as a normal relative path (``./contracts//a.rcl`` is ``contracts/a.rcl``)."""
    return posixpath.normpath(str(file).replace("\\", "/"))


def _same(contract: str, file: str) -> bool:
    """Is the contract file ``contract`` (as the checker names it: relative to
    the workspace, or absolute when the contracts were named so) the plan's
    ``file:`` (relative to the workspace)?"""
    c, f = _path(contract), _path(file)
    return c == f or (posixpath.isabs(c) and not posixpath.isabs(f) and not f.startswith("../")
                      and c.endswith("/" + f))


def check_acknowledgements(acks: Iterable[Acknowledgement], locs: Mapping[Any, ast.Loc],
                           checked: Checked) -> list[Diagnostic]:
    """Located errors (``E-acknowledged``, at the entry's ``file:``/``node:``
    or the entry) of acknowledgements that cannot be tied to one node of one
    contract file of ``checked``: a ``file:`` that is no contract file, a
    node (``node:``, or the node a health id names) the file does not hold,
    or a lint acknowledgement without ``node:`` whose file holds several
    nodes.  ``locs``: the plan's value locations.  Rule: docs/plan.md,
    "Acknowledged warnings"."""
    files: dict[str, list[str]] = {}
    for spec in checked.specs:
        files.setdefault(_path(spec.file), []).extend(n.name for n in spec.nodes)
    diags = []
    for i, a in enumerate(acks):
        if a.file is None:
            continue  # a health id (its node names its file); a lint code without file: is refused on reading
        where = f"acknowledged[{i}] ({a.warning})"
        matched = [names for f, names in files.items() if _same(f, a.file)]
        node, nodes = a.node or health_node(a.warning), (matched[0] if len(matched) == 1 else None)
        if nodes is None:
            diags.append(error(locs.get(("acknowledged", i, "file"), a.loc), f"{where}: file: {a.file} is no contract "
                               f"file of the plan (they are: {', '.join(files)})", "E-acknowledged"))
        elif node is not None and node not in nodes:
            l = locs.get(("acknowledged", i, "node" if a.node else "file"), a.loc)
            diags.append(error(l, f"{where}: {a.file} has no node {node} (it holds: {', '.join(nodes) or 'none'})",
                               "E-acknowledged"))
        elif node is None and len(nodes) > 1:
            diags.append(error(a.loc, f"{where}: {a.file} holds the nodes {', '.join(nodes)}; name the one whose "
                               "warning it answers as node:", "E-acknowledged"))
    return diags


def _within(loc: ast.Loc, line: int, col: int) -> bool:
    end = (loc.end_line, loc.end_col) if loc.end_line else (loc.line, 10**9)
    return (loc.line, loc.col) <= (line, col) < end or (loc.line, loc.col) == (line, col)


def _node_text(node: ast.Node) -> str:
    return to_rcl(ast.Spec((), (node,)))


def lint_flagged(row: LintRow, checked: Checked, source: str = "") -> str:
    """The flagged text of a lint row (its ``location`` ``file:line:col``): the clause or constant whose
    span holds the location, else the node's whole contract, else the source line ``source`` gives, else
    the row's message."""
    file, line, col = _where(row)
    for spec in checked.specs:
        if spec.file != file:
            continue
        for ctx in spec.contexts:
            for d in ctx.decls:
                if isinstance(d, ast.ConstDecl) and _within(d.loc, line, col):
                    return f"{d.name} = {expr_to_rcl(d.value)}"
        for n in spec.nodes:
            if not _within(n.loc, line, col):
                continue
            for c in n.assumes + n.guarantees:
                if _within(c.loc, line, col):
                    return expr_to_rcl(c.formula)
            return _node_text(n)
    return source or row.message


def conjuncts(e: ast.Expr) -> list[ast.Expr]:
    """The top-level ``and`` operands of ``e``, as the health checks number
    them (the plan sits below the calculus, so this is not imported)."""
    if isinstance(e, ast.Binary) and e.op == "and":
        return conjuncts(e.left) + conjuncts(e.right)
    return [e]


def _lint_place(row: LintRow, checked: Checked) -> tuple[str, str | None]:
    """``(file, node)`` of a lint row: its file as :func:`_path` writes it and
    the node whose span holds its location (``None``: outside every node)."""
    file, line, col = _where(row)
    for spec in checked.specs:
        if _same(spec.file, file) or _same(file, spec.file):
            for n in spec.nodes:
                if _within(n.loc, line, col):
                    return _path(file), n.name
    return _path(file), None


#: A row a warning may be: a health finding's or a lint diagnostic's.
Warned = FindingRow | LintRow


def _answers(a: Acknowledgement, row: Warned, checked: Checked) -> bool:
    """Does ``a`` name the finding ``row``: its id (health) or its code, file
    and node (lint)?  Its text is compared by :meth:`Acknowledgement.binds`."""
    if isinstance(row, FindingRow):
        if row.id != a.warning:
            return False
        owner = health_node(a.warning)
        cn = checked.nodes.get(owner or "")
        return (a.node is None or a.node == owner) and (
            a.file is None or (cn is not None and _same(cn.node.loc.file, a.file)))
    if row.code != a.warning or a.file is None:
        return False
    file, node = _lint_place(row, checked)
    return _same(file, a.file) and (a.node is None or node == a.node)


def _where(row: LintRow) -> tuple[str, int, int]:
    """``(file, line, col)`` of a lint row's ``location`` (0 for a line or column it does not give)."""
    file, line, col = (row.location.rsplit(":", 2) + ["0", "0"])[:3]
    return file, int(line) if line.isdigit() else 0, int(col) if col.isdigit() else 0


def health_flagged(finding: FindingRow, checked: Checked) -> str:
    """The flagged text of a health finding: conjunct ``j`` of guarantee
    ``k`` (``<Node>.g<k>.c<j>.<check>``), guarantee ``k``
    (``<Node>.g<k>.<check>``), the node's contract (``<Node>.<check>``), or
    the finding's message when its id names no node of ``checked``."""
    m = _HEALTH_ID.match(finding.id)
    cn = checked.nodes.get(m["node"]) if m else None
    if m is None or cn is None:
        return finding.message
    node = cn.node
    if m["k"] is None:
        return _node_text(node)
    k = int(m["k"])
    if not 1 <= k <= len(node.guarantees):
        return finding.message
    g = node.guarantees[k - 1]
    if m["j"] is None:
        return expr_to_rcl(g.formula)
    parts = conjuncts(g.formula)
    j = int(m["j"])
    return expr_to_rcl(parts[j - 1]) if 1 <= j <= len(parts) else expr_to_rcl(g.formula)


def _word(row: Warned) -> str:
    """What a row is: a health finding's status, a lint diagnostic's severity."""
    return row.status if isinstance(row, FindingRow) else row.severity


def _is_warning(row: Warned) -> bool:
    return _word(row).lower() == "warning"


def _ident(row: Warned) -> str:
    return row.id if isinstance(row, FindingRow) else f"{row.location}:{row.code}"


def _flagged(row: Warned) -> tuple[str, str]:
    """``(flagged text, sha256)`` a row was marked with (:func:`_marked`; ``""`` when it is no warning)."""
    flagged, sha = row.flagged, row.sha256
    return (flagged if isinstance(flagged, str) else ""), (sha if isinstance(sha, str) else "")


def _marked(row: Warned, checked: Checked) -> Warned:
    """``row`` without what an earlier pass marked (rows kept between runs in one process start clean),
    then, when it is a warning, with its flagged text and that text's digest."""
    if isinstance(row, FindingRow):
        clean: Warned = msgspec.structs.replace(row, flagged="", sha256="", acknowledged=None)
    else:
        clean = msgspec.structs.replace(row, flagged=msgspec.UNSET, sha256=msgspec.UNSET, acknowledged=msgspec.UNSET)
    if not _is_warning(clean):
        return clean
    flagged = health_flagged(clean, checked) if isinstance(clean, FindingRow) else lint_flagged(clean, checked)
    return msgspec.structs.replace(clean, flagged=flagged, sha256=digest(flagged))


def apply_acknowledgements(acks: Iterable[Acknowledgement], findings: Iterable[FindingRow],
                           lint_rows: Iterable[LintRow], checked: Checked
                           ) -> tuple[list[FindingRow], list[LintRow], list[AcknowledgementRow]]:
    """Match the plan's acknowledgements with this run's warnings.

    ``findings`` are the report's health rows, ``lint_rows`` its lint rows.
    Returns ``(findings, lint rows, acknowledgements)``: new rows in the
    same order, every warning row with ``flagged`` (its flagged text) and
    ``sha256`` (its digest), and, when an acknowledgement binds it,
    ``acknowledged`` (``reason``, ``at``: the plan entry's
    ``file:line:col``); and one row per acknowledgement with ``status``
    ``ok`` (it acknowledges the ``matched`` warnings), ``stale`` (it
    matches no warning, or the flagged text changed: the warning is raised
    again) or ``error`` (it names an item that is not a warning, or it
    cannot be tied to one finding: a lint code without ``file``, or one
    binding warnings of several nodes; it then accepts none).  A finding is
    matched by its id (health; with ``file``, the node's file too) or by its
    code, file and node (lint), then by its flagged text."""
    given: list[Warned] = [*findings, *lint_rows]
    rows = [_marked(r, checked) for r in given]
    out: list[AcknowledgementRow] = []
    for a in acks:
        cands = [i for i, r in enumerate(rows) if _answers(a, r, checked)]
        warns = [i for i in cands if _is_warning(rows[i])]
        bound = [i for i in warns if a.binds(_flagged(rows[i])[0])]
        owners = {_lint_place(r, checked)[1] for r in (rows[i] for i in bound) if isinstance(r, LintRow)}
        at = f"{a.loc.file}:{a.loc.line}:{a.loc.col}"
        wide = _too_wide(a, owners)
        if wide:
            out.append(AcknowledgementRow(a.warning, a.reason, at, "error", wide, []))
            continue
        for i in bound:
            rows[i] = msgspec.structs.replace(rows[i], acknowledged=Acknowledged(a.reason, at))
        status: AcknowledgementStatus
        if bound:
            status, msg = "ok", f"acknowledges {', '.join(_ident(rows[i]) for i in bound)}: {a.reason}"
        elif warns:
            now = "; ".join(f"`{_flagged(rows[i])[0]}` (sha256 {_flagged(rows[i])[1][:16]})" for i in warns[:3])
            status, msg = "stale", (f"the text it acknowledged changed: {a.warning} now flags {now}; the warning is "
                                    "raised again (read it, then bind the acknowledgement to the new text or drop it)")
        elif cands:
            word = _word(rows[cands[0]])
            status, msg = "error", (f"{a.warning} is {word}, not a warning: only a warning can be acknowledged as an "
                                    "accepted risk (an error or an undecided check must be answered by a fix or evidence)")
        else:
            status, msg = "stale", f"matches no warning of this run ({a.warning}): remove it from the plan"
        out.append(AcknowledgementRow(a.warning, a.reason, at, status, msg, [_ident(rows[i]) for i in bound]))
    return ([r for r in rows if isinstance(r, FindingRow)], [r for r in rows if isinstance(r, LintRow)], out)


def _too_wide(a: Acknowledgement, owners: set[str | None]) -> str:
    """Why ``a`` cannot be tied to one finding ('' when it can): a lint code
    without a file, or one binding warnings of several nodes (``owners``)."""
    if a.file is None and health_node(a.warning) is None:
        return (f"{a.warning} is a lint code with no file: it would answer the warning in every file; give the "
                "contract file (and node:) of the one warning it answers")
    if len(owners) > 1:
        names = ", ".join(sorted(str(o) for o in owners))
        return f"{a.warning} binds warnings of several nodes ({names}); name the one it answers as node:"
    return ""


def hint(row: Warned) -> str:
    """The plan entry that would acknowledge the warning ``row`` (one YAML
    flow mapping; ``reason`` left for the user to write)."""
    name = row.id if isinstance(row, FindingRow) else row.code
    where = ""
    if isinstance(row, LintRow):  # a lint code is tied to its file (node: too when the file holds several nodes)
        where = f"file: {_where(row)[0]}, "
    return f'- {{warning: {name}, {where}sha256: {_flagged(row)[1][:16]}, reason: "..."}}'
