"""A repair checked by Z3 for a liveness requirement refuted because a node
never answers (docs/diagnosis.md, "Refuted temporal requirement").

The temporal check names the nodes a refuting lasso rests on
(``missing_progress``: they accept their input in the loop and never
answer, while the same search with every node answering finds no lasso;
:mod:`rclverify.calculus.requirements.progress_gap`).  The repair is the missing
declaration, ``progress( within K steps )`` on that node, added to its
contract (or replacing its ``progress( eventually )``, which excludes the
lasso but bounds nothing, so proves nothing); the requirement is checked
again on the edited contracts by the requirement check itself
(:func:`rclverify.calculus.requirements.check.check_requirement`) and the repair is
offered only when it is then ``proved``.  The bounds are tried weakest
first (:data:`BOUNDS`: a larger K asks less of the node) and the first that
proves is offered: the claim the implementation must meet is the weakest
that suffices.

What Z3 shows is that the requirement follows once the node answers within
K steps; not that it does: a progress declaration is a claim about the
implementation, which no backend checks yet (the requirement stays
``proved, evidence outstanding``, the declaration ``pending``).
"""
from __future__ import annotations

from typing import Any

from rclverify.semantics import world
from rclverify.diagnosis import recheck
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import _record
from rclverify.calculus.shapes import Gaps
from rclverify.records.requirement_rows import RequirementRow
from rclverify.records.stage_records import Repair
from rclverify.model.plan.load import all_requirements
from rclverify.calculus.requirements.check import check_requirement

#: The step bounds tried, weakest first (a larger K is a weaker claim).
BOUNDS = (3, 1, 0)
#: At most this many nodes of ``missing_progress`` are tried (each costs up to len(BOUNDS) temporal checks).
MAX_NODES = 2


def _declaration_edit(ws: Any, node: Any, k: int) -> Edit | None:
    """The edit giving ``node`` (a parsed RCL node) ``progress( within k
    steps )``: replacing a ``progress( eventually )`` it declares, else
    inserted on a line of its own before the node's closing brace (after
    its other clauses, where ``fmt`` prints it); ``None`` without exact
    locations or with a bounded progress already declared."""
    text = f"progress( within {k} steps )"
    source = recheck.source_text(ws, node.loc.file)
    lines = source.splitlines(keepends=True)
    if node.progress:
        p = node.progress[0]
        if p.bound is not None or not p.loc.line:
            return None
        line = lines[p.loc.line - 1]
        close = line.find(")", p.loc.col - 1)
        if close < 0:
            return None
        return Edit(node.loc.file, p.loc.line, p.loc.col, p.loc.line, close + 2, text)
    end_line, end_col = node.loc.end_line, node.loc.end_col
    if not end_line or end_line > len(lines):
        return None
    brace = end_col - 2  # 0-based index of the closing "}"
    head = lines[end_line - 1][:brace]
    if head.strip():  # "}" after other text on its line: insert before it on the same line
        return Edit(node.loc.file, end_line, brace + 1, end_line, brace + 1, f" {text} ")
    return Edit(node.loc.file, end_line, 1, end_line, 1, f"  {text}\n")


def progress_repairs(ws: Any, q: RequirementRow, temporal: Gaps) -> list[Repair]:
    """The repairs (:func:`.repairs._record` dicts, kind
    ``declare-progress``) for the refuted temporal requirement ``q`` (the
    report's record) whose check ``temporal`` names ``missing_progress``: for
    each such node (at most :data:`MAX_NODES`), the weakest ``progress(
    within K steps )`` (:data:`BOUNDS`) with which the requirement check
    proves ``q`` on the edited contracts.  ``[]`` when none does, when the
    requirement or a node cannot be found, or the edited text does not
    check."""
    req = next((r for r in all_requirements(ws.plan) if r.id == q.id), None)
    if req is None:
        return []
    out = []
    for gap in list(temporal.get("missing_progress") or [])[:MAX_NODES]:
        cn = ws.checked.nodes.get(str(gap["node"]))
        if cn is None:
            continue
        for k in BOUNDS:
            edit = _declaration_edit(ws, cn.node, k)
            if edit is None:
                break
            system = recheck.edited_system(ws, edit)
            if system is None:
                break
            world.fresh()
            rec = check_requirement(req, system[0], system[1], ws.plan)
            t = rec.get("temporal") or {}
            if t.get("status") != "proved":
                continue
            how = f"{t.get('method')}" + (f", k = {t['k']}" if t.get("k") is not None else "")
            node = str(gap["node"])
            summary = (f"Declare on {node} ({gap['source']}) `progress( within {k} steps )`: it answers every input "
                       f"its assumption accepts within {k} step{'s' if k != 1 else ''}, the weakest such claim of "
                       f"those tried ({', '.join(str(b) for b in BOUNDS)}) with which {q.id} is proved. Declare "
                       f"it only if {node}'s implementation does answer so: it is a claim its evidence must show.")
            out.append(_record("declare-progress", summary, edit, recheck.source_text(ws, edit.file),
                               [{"check": q.id, "status": f"proved (temporal check: {how})"}],
                               [{"check": q.id, "before": "refuted", "after": "proved"}],
                               proves=f"{q.id} follows from the edited contracts (every run reaches it)",
                               not_shown=f"that {node} answers within {k} step{'s' if k != 1 else ''}: a claim "
                                         "about its implementation, which no backend checks yet (declared, not "
                                         "verified)"))
            break
    return out
