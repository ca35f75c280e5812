"""The one-token repair of a refuted Hoare triple's program (docs/diagnosis.md, "Refuted Hoare triple: the
one-token correction"), checked by Z3 as the backend checks the triple.

When the program's constants are not what is wrong (:mod:`.constants` finds no change), the slip may be an
operator: ``<`` written for ``<=``, ``and`` for ``or``, ``-`` for ``+``, or a number off by one.  Here:

1. *The candidates* (:func:`token_edits`): in the program's statements (the conditions of ``if`` and
   ``while``, the assigned values; never a loop invariant, which is the proof's, not the program's), each
   comparison's strictness flipped (``<``/``<=``, ``>``/``>=``), ``and``/``or`` and ``+``/``-`` swapped,
   each an edit of the operator's token alone; then each integral number moved by one.  Operators first,
   then numbers; in source order.
2. *The check*: the edited program is written to a temporary copy
   (:func:`rclverify.diagnosis.recheck.hoare_statuses`, the workspace is never written) and every triple
   of its plan entry is asked again of Z3.  A candidate is kept when none is ``failed`` or
   ``inconclusive`` and at least one is ``discharged`` (a triple pending for what the program does not
   model stays pending).  At most :data:`MAX_KEPT` are kept, of at most :data:`MAX_TRIED` tried.

What Z3 shows is that every triple of the program holds of the edited text (the VCs proved), not that the
edit is the right one for the robot.
"""
from __future__ import annotations

import re
from typing import Any, Iterator, Mapping

from rclverify.diagnosis import recheck
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import _record
from rclverify.records.stage_records import Repair

#: Most candidates asked of Z3 for one program (each asks every triple of the entry).
MAX_TRIED = 12
#: Most repairs kept.
MAX_KEPT = 2
#: Each operator's one-token correction.
_SWAP = {"<": "<=", "<=": "<", ">": ">=", ">=": ">", "and": "or", "or": "and", "+": "-", "-": "+"}
_OP = re.compile(r"<=|>=|<|>|\band\b|\bor\b|\+|-")


def _offset(lines: list[str], line: int, col: int) -> int:
    return sum(len(x) for x in lines[:line - 1]) + col - 1


def _position(lines: list[str], offset: int) -> tuple[int, int]:
    """The 1-based (line, column) of the character at ``offset`` of the text split into ``lines``."""
    for k, text in enumerate(lines, 1):
        if offset < len(text):
            return k, offset + 1
        offset -= len(text)
    return len(lines), len(lines[-1]) + 1 if lines else 1


def _expressions(stmts: Any) -> Iterator[Any]:
    """The expressions of the program's statements (conditions and assigned values; no invariant)."""
    for s in stmts:
        kind = type(s).__name__
        if kind == "Assign":
            yield s.value
        elif kind == "If":
            yield s.cond
            yield from _expressions(s.then_)
            yield from _expressions(s.else_)
        elif kind == "While":
            yield s.cond
            yield from _expressions(s.body)


def _walk(e: Any) -> Iterator[Any]:
    yield e
    for f in ("left", "right", "operand"):
        sub = getattr(e, f, None)
        if sub is not None:
            yield from _walk(sub)
    for a in getattr(e, "args", ()) or ():
        yield from _walk(a)


def token_edits(source: str, program: str, prog: Any) -> list[Edit]:
    """The one-token corrections of ``prog`` (the parsed ``source`` of the file ``program``), operators
    first, then numbers moved by one, each in source order, each once (module docstring, step 1)."""
    lines = source.splitlines(keepends=True)
    ops: list[Edit] = []
    nums: list[Edit] = []
    for e in (x for root in _expressions(prog.body) for x in _walk(root)):
        kind = type(e).__name__
        if kind == "Binary" and e.op in _SWAP and e.left.loc.end_line and e.right.loc.line:
            a = _offset(lines, e.left.loc.end_line, e.left.loc.end_col)
            b = _offset(lines, e.right.loc.line, e.right.loc.col)
            m = _OP.search(source, a, b)
            if m is not None and m.group() == e.op:
                line, col = _position(lines, m.start())
                ops.append(Edit(program, line, col, line, col + len(m.group()), _SWAP[e.op]))
        elif kind == "Num" and e.is_integral and e.loc.end_line:
            for d in (-1, 1):
                if int(e.text) + d >= 0:
                    nums.append(Edit(program, e.loc.line, e.loc.col, e.loc.end_line, e.loc.end_col,
                                     str(int(e.text) + d)))
    out: list[Edit] = []
    seen: set[tuple[int, int, str]] = set()
    for ed in sorted(ops, key=lambda x: (x.line, x.col)) + sorted(nums, key=lambda x: (x.line, x.col)):
        if (ed.line, ed.col, ed.text) not in seen:
            seen.add((ed.line, ed.col, ed.text))
            out.append(ed)
    return out


def hoare_token_repairs(ws: Any, node: str, guarantee: int, program: str,
                        before: Mapping[str, str]) -> list[Repair]:
    """The checked one-token repairs (module docstring) of the program ``program`` whose triple for
    guarantee ``guarantee`` of ``node`` is refuted; ``before`` maps the entry's obligation ids to their
    statuses (for each repair's cost).  ``[]`` when the program is in no Hoare entry of ``node``, does
    not parse, or no candidate passes."""
    from rclverify.backends.hoare import lang  # deferred: start-up (loads jinja2, z3 and more only when called)
    idx = next((i for i, e in enumerate(ws.plan.evidence.get(node, ()))
                if e.backend == "hoare" and e.config.get("program") == program), None)
    if idx is None:
        return []
    source = recheck.source_text(ws, program)
    try:
        prog = lang.parse_program(source, program)
    except Exception:  # noqa: BLE001 - a program that no longer parses: the backend's own run says why
        return []
    out: list[Repair] = []
    for edit in token_edits(source, program, prog)[:MAX_TRIED]:
        after = recheck.hoare_statuses(ws, node, idx, program, edit.apply(source))
        if not after or any(s not in ("discharged", "pending") for s in after.values()) \
                or not any(s == "discharged" for s in after.values()):
            continue
        old = source.splitlines()[edit.line - 1].strip()
        new = edit.apply(source).splitlines()[edit.line - 1].strip()
        checks, counted = recheck.triple_checks(after)
        out.append(_record(
            "program",
            f"At {program}:{edit.line}, change `{old}` to `{new}`: a one-token correction of the program; Z3 "
            f"then discharges every triple of it ({counted}).",
            edit, source, checks, recheck.changes(before, after),
            proves=f"every triple of {program} holds of the edited program (Z3 proved its verification conditions)",
            not_shown=f"that the edit is right for the robot, nor that {program} still models the node's code"))
        if len(out) >= MAX_KEPT:
            break
    return out


__all__ = ["MAX_KEPT", "MAX_TRIED", "hoare_token_repairs", "token_edits"]
