"""Checked repairs of a node's code for a monitor's violation on a
recorded run (docs/diagnosis.md, "Monitor violations: a node re-run on its
recorded run").

A node whose answers on a recorded run (a live monitor's log) violate its
contract, and whose source is a Python file of the workspace making rclpy
nodes, is repaired the way a failing property test is
(:mod:`.code_repair`), with the run as the evidence:

1. *The node is re-run* (:mod:`.rerun`): its callback, found through rclpy's
   own lists in the robot the file's factory makes, is called on every
   question the run recorded for it (the messages of its input topics, its
   calls' requests, its goals).  The recorded source must give the recorded
   answers again, field by field, or nothing is offered: a node whose
   answers depend on more than its questions (a clock, a state fed by
   another topic) cannot be re-run on them.
2. *The candidates* (:func:`candidate_edits`): the one-token corrections
   (the property tests' culprit search's, ``max``/``min`` swapped, a slice
   dropped, a truth value or name replaced by a field of a message the
   callback reads) of the callback's expressions and of the assignments, in
   its enclosing function, of the names it reads from there (``cap = 1.2``
   read by ``govern``: the value is made there), ranked as the property
   tests' are: an operator or a name first, then a number moved by one, then
   a number the contract names, then the rest; then smallest; then in
   source order.  At most :data:`MAX_TRIED`, each within :data:`SLOWER` times
   the recorded source's re-run (at least :data:`MIN_BOUND_S` seconds).
3. *The check* (:func:`run_repairs`): each candidate text is re-run on the
   questions, its answers replace the node's recorded ones
   (:func:`.rerun.rewritten`), and the whole run is judged again by the
   monitors backend (:func:`rclverify.backends.monitors.recorded.check_recorded`,
   every node of the contracts).  A candidate is kept when every verdict of
   the node that failed is ``discharged``, none of its others got worse, and
   every other node's verdicts and counts are the recorded run's: a repair
   that changes what another node hears is not offered, since that node's
   recorded answers were to the old messages.
4. At most :data:`MAX_REPAIRS` are kept, each a ``code`` repair whose text
   says which run checked it and what that does not show.

The line the diagnosis names (:attr:`RunRepairs.line`): the line the first
checked repair edits, else the callback's first line.  Nothing here raises
for the user's code or run: a node that cannot be re-run is
:attr:`RunRepairs.why`.
"""
from __future__ import annotations

import ast
import shutil
import tempfile
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping, Sequence

from rclverify.diagnosis.code_repair import _NONE, _SWAP, _edit, _rank
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.rerun import (AgentAnswer, RerunError, endpoint, questions, read_run, reproduces,
                                       rerun, rewritten, write_run)
from rclverify.records.stage_records import Repair

#: Most repairs offered for one violation.
MAX_REPAIRS = 3
#: Most candidates re-run on the recorded run for one violation.
MAX_TRIED = 24
#: A candidate may take this many times the recorded source's re-run ...
SLOWER = 4.0
#: ... and at least this many seconds (a callback that sleeps or loops longer is not a repair).
MIN_BOUND_S = 2.0
#: The verdicts a repaired node's items may end at.
_GOOD = ("discharged",)


@dataclass
class RunRepairs:
    """The outcome of :func:`run_repairs`: the checked ``repairs`` (best first), the ``line`` the diagnosis
    names (``file:line``; ``""`` when the node was not re-run), the ``tried`` candidates and ``why`` none
    was offered (``""`` when one was)."""

    repairs: list[Repair] = field(default_factory=list)
    line: str = ""
    tried: int = 0
    why: str = ""


def _roots(tree: ast.Module, line: int, name: str, freevars: Sequence[str]) -> tuple[list[ast.expr], set[str]]:
    """The expressions a repair of the callback at ``line`` (``name``: its code's name, ``<lambda>`` for a
    lambda) may edit: the callback's own and the values assigned, in the function enclosing it, to the
    names it reads from there (``freevars``); and the callback's parameters."""
    found: list[tuple[ast.AST, ast.AST | None]] = []  # (callback, its enclosing function)

    def visit(n: ast.AST, outer: ast.AST | None) -> None:
        for c in ast.iter_child_nodes(n):
            here = isinstance(c, ast.Lambda) and name == "<lambda>" or \
                isinstance(c, (ast.FunctionDef, ast.AsyncFunctionDef)) and c.name == name
            first = min([getattr(c, "lineno", 0), *(d.lineno for d in getattr(c, "decorator_list", []))]) if here else 0
            if here and (getattr(c, "lineno", 0) == line or first == line):
                found.append((c, outer))
            visit(c, c if isinstance(c, (ast.FunctionDef, ast.AsyncFunctionDef)) else outer)
    visit(tree, None)
    roots: list[ast.expr] = []
    params: set[str] = set()
    for cb, outer in found:
        args = getattr(cb, "args", None)
        if isinstance(args, ast.arguments):
            params |= {a.arg for a in (*args.posonlyargs, *args.args, *args.kwonlyargs)}
        roots.extend([cb.body] if isinstance(cb, ast.Lambda) else
                     [e for s in ast.walk(cb) if isinstance(s, ast.stmt) for e in _values(s)])
        for s in ast.walk(outer) if outer is not None else ():
            if isinstance(s, ast.Assign) and any(isinstance(t, ast.Name) and t.id in freevars for t in s.targets):
                roots.append(s.value)
    return roots, params


def _values(s: ast.stmt) -> list[ast.expr]:
    if isinstance(s, (ast.Return, ast.Assign, ast.AugAssign, ast.AnnAssign, ast.Expr)):
        return [s.value] if s.value is not None else []
    if isinstance(s, (ast.If, ast.While)):
        return [s.test]
    return []


def _params(roots: Sequence[ast.expr], params: set[str]) -> list[str]:
    """The fields of messages the callback reads (``req.data``): attributes of its parameters ``params``
    read in ``roots``, each once, in source order."""
    out: list[str] = []
    for r in roots:
        for n in ast.walk(r):
            if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and isinstance(n.ctx, ast.Load) \
                    and n.value.id in params:
                out.append(ast.unparse(n))
    return list(dict.fromkeys(out))


def candidate_edits(source: str, file: str, line: int, name: str, freevars: Sequence[str],
                    numbers: Sequence[Fraction]) -> list[Edit]:
    """The one-token corrections (module docstring, step 2) of the callback named ``name`` whose code
    starts at ``line`` of ``source`` (the file ``file``), ranked; ``[]`` when the file does not parse or
    holds no such callback."""
    from rclverify.backends.property_tests.slips import mutations  # deferred: start-up (the backend's search)
    try:
        tree = ast.parse(source, file)
    except (SyntaxError, ValueError):
        return []
    lines = source.splitlines(keepends=True)
    roots, params = _roots(tree, line, name, freevars)
    reads = _params(roots, params)
    ranked: list[tuple[int, Edit]] = []
    for root in roots:
        holder = ast.FunctionDef(name="_", args=ast.arguments(posonlyargs=[], args=[], kwonlyargs=[],
                                                                kw_defaults=[], defaults=[]),
                                 body=[ast.Return(value=root, lineno=getattr(root, "lineno", 1))],
                                 decorator_list=[])
        nodes = list(ast.walk(holder))
        for m in mutations(holder, holder.body[0], numbers):
            e = _edit(file, lines, nodes[m.index], ast.unparse(m.new))
            if e is not None:
                ranked.append((_rank(e.deleted(source), e.text), e))
        for n in ast.walk(root):
            if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id in _SWAP:
                ranked.append((0, _edit(file, lines, n.func, _SWAP[n.func.id]) or _NONE))
            elif isinstance(n, ast.Subscript) and isinstance(n.slice, ast.Slice):
                ranked.append((3, _edit(file, lines, n, ast.unparse(n.value)) or _NONE))
            elif isinstance(n, ast.Constant) and isinstance(n.value, bool):
                ranked.extend((3, _edit(file, lines, n, r) or _NONE) for r in reads)
    seen: set[tuple[int, int, int, int, str]] = set()
    out: list[tuple[int, Edit]] = []
    for cls, e in ranked:
        key = (e.line, e.col, e.end_line, e.end_col, e.text)
        if e is not _NONE and key not in seen:
            seen.add(key)
            out.append((cls, e))
    return [e for _, e in sorted(out, key=lambda ce: (ce[0], len(ce[1].deleted(source)) + len(ce[1].text),
                                                      ce[1].line, ce[1].col))]


#: One judged item: its status and its verdict counts, sorted.
Judged = tuple[str, tuple[tuple[str, int], ...]]


def judged(checked: Any, cfg: Any, root: Path, run: Path) -> dict[str, Judged]:
    """Every verdict of the run at ``run`` judged again by the monitors backend against every node of
    ``checked`` (``cfg``: the monitor configuration): ``item -> (status, counts)``, the items a node's
    messages (``Node``), its calls (``Node calls``), its topics' deadlines (``Node deadlines``, status
    ``""``) and its calls' deadlines (``Node call deadlines``)."""
    from rclverify.backends.monitors.recorded import check_recorded  # deferred: start-up (the monitors)
    got = check_recorded(checked, list(checked.nodes.values()), cfg, root, str(run), lambda _w: None)
    out: dict[str, Judged] = {}
    for res in got.results:
        out[res.node] = (got.verdict(res, str(run))[0], tuple(sorted(res.counts.items())))
    for c in got.call_entries:
        out[f"{c['node']} calls"] = (str(c["status"]), ())
    for d in got.deadlines:
        out[f"{d.node} deadlines"] = ("", tuple(sorted(d.counts.items())))
    for c in got.deadline_entries:
        out[f"{c['node']} call deadlines"] = (str(c["status"]), tuple(sorted(c["call_deadlines"]["counts"].items())))
    return out


def _mine(node: str, item: str) -> bool:
    return item == node or item.startswith(node + " ")


def _bad(j: Judged) -> bool:
    """A failed item, or deadlines missed."""
    return j[0] == "failed" or dict(j[1]).get("false", 0) > 0


def _kept(node: str, before: Mapping[str, Judged], after: Mapping[str, Judged]) -> bool:
    """Whether ``after`` (the run judged with a candidate) repairs ``node`` (module docstring, step 3):
    ``node`` had a failed item, has none now and no item of it left ``discharged``; every other item is
    as it was."""
    if set(before) != set(after) or not any(_bad(before[k]) for k in before if _mine(node, k)):
        return False
    for k in before:
        if not _mine(node, k):
            if before[k] != after[k]:
                return False
        elif _bad(after[k]) or before[k][0] in _GOOD and after[k][0] not in _GOOD \
                or _bad(before[k]) and after[k][0] not in (*_GOOD, ""):
            return False
    return True


def run_repairs(root: Path, checked: Any, cfg: Any, trace: Path, node: str, calls: bool, source: str,
                factory: str, args: Sequence[Any], python: Path) -> RunRepairs:
    """The checked repairs (module docstring) of contract node ``node``'s violation on the run ``trace``
    (a JSON-lines log; ``calls``: the violation is of its served service or action, else of its topics),
    whose code is the workspace file ``source`` (relative to ``root``) whose function ``factory(*args)``
    makes the robot's rclpy nodes, re-run in the ROS 2 Python ``python``; ``checked`` the workspace's
    checked contracts, ``cfg`` the monitor configuration (:func:`rclverify.backends.monitors.config.load_mapping`)."""
    from rclverify.backends.property_tests.boundary import contract_numbers  # deferred: start-up (the backend)
    path = root / source
    try:
        text = path.read_text(encoding="utf-8")
        ep = endpoint(checked.nodes[node], calls)
        lines = read_run(trace)
        asked = questions(lines, ep)
        if not asked:
            return RunRepairs(why=f"the run records no question of {node} to re-run it on")
        first = rerun(python, path, [text], factory, args, ep, asked)
    except (OSError, UnicodeDecodeError, KeyError) as e:
        return RunRepairs(why=f"{node} cannot be re-run: {type(e).__name__}: {e}")
    except RerunError as e:
        return RunRepairs(why=str(e))
    cb, run0 = first.callback, first.first()
    if run0.error or cb is None:
        said = run0.error or "no callback found"
        return RunRepairs(why=f"{source} did not answer {node}'s questions when re-run: {said}")
    at = f"{source}:{cb.line}"
    if not reproduces(lines, ep, run0.answers):
        return RunRepairs(line=at, why=f"re-run on the run's questions, {source} does not give the recorded "
                          f"answers of {node} again: they depend on more than its questions, or the code changed "
                          "since the run was recorded (record it again)")
    edits = candidate_edits(text, source, cb.line, cb.name, cb.freevars,
                            contract_numbers(checked.nodes[node]))[:MAX_TRIED]
    tmp = Path(tempfile.mkdtemp(prefix="rclverify-run-repair-"))
    try:
        before = judged(checked, cfg, root, write_run(rewritten(lines, ep, run0.answers), tmp / "recorded.jsonl"))
        bound = max(MIN_BOUND_S, SLOWER * run0.seconds)
        got = rerun(python, path, [e.apply(text) for e in edits], factory, args, ep, asked, bound) if edits \
            else AgentAnswer()
        out: list[Repair] = []
        for k, (edit, ran) in enumerate(zip(edits, got.runs)):
            if ran.error:
                continue
            try:
                after = judged(checked, cfg, root, write_run(rewritten(lines, ep, ran.answers), tmp / f"c{k}.jsonl"))
            except RerunError:
                continue
            except Exception:  # noqa: BLE001 - a rewritten run the monitors refuse: not a repair
                continue
            if _kept(node, before, after):
                out.append(_repair(node, source, text, edit, trace, before, after, asked))
                if len(out) >= MAX_REPAIRS:
                    break
    except RerunError as e:
        return RunRepairs(line=at, tried=len(edits), why=str(e))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    line = f"{source}:{out[0]['edit']['line']}" if out else at
    why = "" if out else f"none of the {len(edits)} one-token corrections tried made {node}'s verdicts on the run " \
        "discharged without changing another node's"
    return RunRepairs(out, line, len(edits), why)


def rejudged(root: Path, checked: Any, cfg: Any, trace: Path, node: str, calls: bool, source: str, text: str,
             factory: str, args: Sequence[Any], python: Path) -> dict[str, Judged]:
    """The run ``trace`` judged again (:func:`judged`) with ``node``'s answers those of its callback re-run
    from ``text`` (the file ``source`` as it would read) made by ``factory(*args)``; the arguments as
    :func:`run_repairs` takes them.  Raises :class:`.rerun.RerunError` when the text does not answer."""
    ep = endpoint(checked.nodes[node], calls)
    lines = read_run(trace)
    got = rerun(python, root / source, [text], factory, args, ep, questions(lines, ep))
    ran = got.first()
    if ran.error:
        raise RerunError(f"{source} did not answer {node}'s questions: {ran.error}")
    with tempfile.TemporaryDirectory(prefix="rclverify-run-repair-") as tmp:
        return judged(checked, cfg, root, write_run(rewritten(lines, ep, ran.answers), Path(tmp) / "run.jsonl"))


def _repair(node: str, source: str, text: str, edit: Edit, trace: Path, before: Mapping[str, Judged],
            after: Mapping[str, Judged], asked: Sequence[Any]) -> Repair:
    from rclverify.diagnosis.repairs import _record  # deferred: start-up (z3 and the contract checks)
    old = text.splitlines()[edit.line - 1].strip()
    new = edit.apply(text).splitlines()[edit.line - 1].strip()
    checks = [{"check": k, "status": after[k][0] or _said(after[k])} for k in sorted(after) if _mine(node, k)]
    cost = [{"check": k, "before": before[k][0] or _said(before[k]), "after": after[k][0] or _said(after[k])}
            for k in sorted(after) if before[k] != after[k]]
    rec = _record("code", f"At {source}:{edit.line}, change `{old}` to `{new}`: a one-token correction of the "
                  f"code that answers {node}'s questions.", edit, text, checks, cost,
                  proves=f"{node}'s callback, edited and re-run on the {len(asked)} questions recorded in "
                  f"{trace.name}, answers them so that the monitors judge every verdict of {node} on that run "
                  "discharged, every other node's as recorded",
                  not_shown="that the edit is right on other runs: the run's questions are all it was re-run on, "
                  "at the recorded times")
    rec["checked_by"] = "the monitors backend on the recorded run, the node re-run in rclpy"
    return rec


def _said(j: Judged) -> str:
    """A deadline item's counts in words (``true 3, false 0``)."""
    return ", ".join(f"{v} {n}" for v, n in j[1])


__all__ = ["Judged", "MAX_REPAIRS", "MAX_TRIED", "MIN_BOUND_S", "SLOWER", "RunRepairs", "candidate_edits", "judged",
           "rejudged", "run_repairs"]

