"""The repair of a refuted Hoare triple: the program's constants changed to
the guarantee's (docs/diagnosis.md, "Refuted Hoare triple: the constant
change").  Numeric literals of the program that the guarantee does not use
are replaced by literals of the guarantee, fewest replacements first and
keeping their order (a larger threshold stays larger), until Z3 discharges
every triple of the program's plan entry.  Only thresholds are exchanged: a
program literal compared with something (``IF (input < 10)``) for a bound
of the guarantee (:func:`.bounds.bound_literals`), never a coefficient or
a scale factor of either.  The edited program is written to a temporary
directory (:func:`rclverify.diagnosis.recheck.hoare_statuses`), never over
the workspace's."""
from __future__ import annotations

import itertools
from typing import Any, Mapping, Sequence

from rclverify.diagnosis import recheck
from rclverify.diagnosis.bounds import bound_literals
from rclverify.diagnosis.edits import Edit
from rclverify.diagnosis.repairs import MAX_CANDIDATES, _record
from rclverify.lang.ast import Loc
from rclverify.records.stage_records import Repair

_ORDERING = ("<", "<=", ">", ">=")


def _thresholds(e: Any) -> list[Any]:
    """The numeric literals of a Hoare program (any node of
    :mod:`rclverify.backends.hoare.lang`) that are a direct operand of an
    ordering comparison, in source order."""
    out: list[Any] = []
    todo = [e]
    while todo:
        x = todo.pop()
        if isinstance(x, (tuple, list)):
            todo.extend(x)
            continue
        if not hasattr(x, "__dataclass_fields__"):
            continue
        if type(x).__name__ == "Binary" and getattr(x, "op", None) in _ORDERING:
            out += [o for o in (x.left, x.right) if type(o).__name__ == "Num" and getattr(o, "loc", None) is not None]
        todo.extend(getattr(x, f) for f in x.__dataclass_fields__ if f != "loc")
    return sorted(out, key=lambda n: (n.loc.line, n.loc.col))


def _num_value(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def hoare_repair(ws: Any, node: str, guarantee: int, program: str,
                 before: Mapping[str, str]) -> Repair | None:
    """The change of program constants (to constants of guarantee
    ``guarantee`` of ``node``) under which every triple of the plan entry of
    ``program`` is discharged, fewest changes first; ``None`` when none
    passes.  ``before`` maps the entry's obligation ids to their statuses."""
    from rclverify.backends.hoare import lang  # deferred: start-up (loads jinja2, z3 and more only when called)
    idx = next((i for i, e in enumerate(ws.plan.evidence.get(node, ()))
                if e.backend == "hoare" and e.config.get("program") == program), None)
    if idx is None:
        return None
    source = recheck.source_text(ws, program)
    prog = lang.parse_program(source, program)
    prog_nums = [n for n in _thresholds(prog.body) if n.loc.end_line]
    g = ws.checked.nodes[node].node.guarantees[guarantee - 1]
    contract = []
    for n in bound_literals(g.formula):
        if n.text not in contract:
            contract.append(n.text)
    distinct = sorted({n.text for n in prog_nums if n.text not in contract}, key=_num_value)
    if not distinct or not contract:
        return None
    tried = 0
    for size in range(1, len(distinct) + 1):
        for olds in itertools.combinations(distinct, size):
            for news in itertools.product(contract, repeat=size):
                if tried >= MAX_CANDIDATES * 4:
                    return None
                # keep the order of the thresholds: a larger constant stays larger
                if list(news) != sorted(news, key=_num_value) or len(set(news)) != size:
                    continue
                tried += 1
                mapping = dict(zip(olds, news))
                new_text = _replace_numbers(source, prog_nums, mapping)
                after = recheck.hoare_statuses(ws, node, idx, program, new_text)
                if not after or any(s not in ("discharged", "pending") for s in after.values()):
                    continue
                if not any(s == "discharged" for s in after.values()):
                    continue
                first = [n for n in prog_nums if n.text in mapping]
                lo = min(first, key=lambda n: (n.loc.line, n.loc.col))
                hi = max(first, key=lambda n: (n.loc.end_line, n.loc.end_col))
                span = Edit(program, lo.loc.line, lo.loc.col, hi.loc.end_line, hi.loc.end_col, "")
                region = span.deleted(source)
                edit = Edit(program, lo.loc.line, lo.loc.col, hi.loc.end_line, hi.loc.end_col,
                            _replace_numbers(region, [_shift(n, lo) for n in first], mapping))
                said = ", ".join(f"{a} -> {b}" for a, b in mapping.items())
                checks, counted = recheck.triple_checks(after)
                return _record(
                    "constant",
                    f"Change the constants of {program}: {said} (the constants of guarantee {guarantee} of "
                    f"{node}); Z3 then discharges every triple of the program ({counted}).",
                    edit, source, checks, recheck.changes(before, after))
    return None


class _At:
    def __init__(self, text: str, line: int, col: int, end_line: int, end_col: int) -> None:
        self.text = text
        self.loc = Loc("", line, col, end_line, end_col)


def _shift(n: Any, lo: Any) -> _At:
    """``n``'s location relative to the start of ``lo`` (line 1, col 1)."""
    line = n.loc.line - lo.loc.line + 1
    col = n.loc.col - (lo.loc.col - 1 if n.loc.line == lo.loc.line else 0)
    end_col = n.loc.end_col - (lo.loc.col - 1 if n.loc.end_line == lo.loc.line else 0)
    return _At(n.text, line, col, n.loc.end_line - lo.loc.line + 1, end_col)


def _replace_numbers(text: str, nums: Sequence[Any], mapping: Mapping[str, str]) -> str:
    """``text`` with each literal of ``nums`` whose text ``mapping`` names
    replaced (from the last to the first, so earlier positions hold)."""
    for n in sorted(nums, key=lambda n: (n.loc.line, n.loc.col), reverse=True):
        if n.text in mapping:
            text = Edit("", n.loc.line, n.loc.col, n.loc.end_line, n.loc.end_col, mapping[n.text]).apply(text)
    return text
