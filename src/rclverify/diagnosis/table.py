"""Counterexamples and witnesses as small tables (variable, value, node).

A Z3 model arrives in RCL names (:func:`rclverify.semantics.query.render_model`):
``{"Agent.in.wayP": "{(p1, p2) -> (if ((p2 == 2) and ...) then 1 else ...)}"}``.
Function-typed values become their finite table: one row per point the
interpretation names (the positive equalities of each ``if`` branch), then
the ``else`` value; a table longer than :data:`MAX_ROWS` rows is cut and
the rest counted.  When a branch is not one point (a disjunction, or an
argument it leaves free) the text is not a table, and it is shown as it is
(cut): reading the last ``else`` as the value "elsewhere" would be false.  Exact rationals are printed as decimals (``0.2``, not
``1/5``; :func:`decimal_text`).  Nothing is ever shown as nested
if-then-else text.
"""
from __future__ import annotations

import re
from fractions import Fraction
from typing import Mapping

import msgspec

from rclverify.records.repair_rows import CexTableRow
from rclverify.records.stage_records import CexRow, FunctionTable
from rclverify.semantics.values import decimal_text

#: Most rows of one function table; the rest are counted ("... and 40 more points").
MAX_ROWS = 8
#: Longest value text shown in a cell; a longer one is cut with its length said.
MAX_VALUE = 120

_RATIONAL = re.compile(r"(?<![\w.])(-?\d+)/(\d+)(?![\w.])")


def decimals(text: str) -> str:
    """``text`` with every ``p/q`` rational that has an exact decimal written
    as that decimal (``move(1/5, 3/2)`` -> ``move(0.2, 1.5)``); ``1/3`` stays."""
    def one(m: re.Match[str]) -> str:
        q = int(m.group(2))
        if q == 0:
            return m.group(0)
        dec = decimal_text(Fraction(int(m.group(1)), q))
        return dec if dec is not None else m.group(0)
    return _RATIONAL.sub(one, text)


def _balanced(s: str, i: int) -> int:
    """Index one past the parenthesised group opening at ``s[i] == '('``."""
    depth = 0
    for j in range(i, len(s)):
        c = s[j]
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(s)


def _split_top(s: str, sep: str = ",") -> list[str]:
    out, depth, start = [], 0, 0
    for j, c in enumerate(s):
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == sep and depth == 0:
            out.append(s[start:j].strip())
            start = j + 1
    out.append(s[start:].strip())
    return [x for x in out if x]


_EQ = re.compile(r"^\(?\s*(p\d+)\s*==\s*(.+?)\s*\)?$")


def _point(cond: str, params: list[str]) -> str:
    """The argument tuple an ``if`` condition pins down: its positive
    ``pK == v`` atoms (``not (...)`` atoms only exclude points); a parameter
    left free is ``*``."""
    fixed: dict[str, str] = {}
    body = cond.strip()
    if body.startswith("(") and _balanced(body, 0) == len(body):
        body = body[1:-1]
    for atom in re.split(r"\s+and\s+", body):
        a = atom.strip()
        if a.startswith("not"):
            continue
        m = _EQ.match(a)
        if m and m.group(1) in params:
            fixed[m.group(1)] = decimals(m.group(2).strip("() "))
    args = [fixed.get(p, "*") for p in params]
    return "(" + ", ".join(args) + ")"


def function_table(text: str, max_rows: int = MAX_ROWS) -> FunctionTable | None:
    """The finite table of a function value written as ``{(a, b) -> v, ...,
    else -> w}`` or ``{(p1, p2) -> (if (...) then v else ...)}``: ``{"rows":
    [[args, value], ...], "more": n, "else": w}``; ``None`` when ``text`` is
    not a function value."""
    t = text.strip().replace("|->", "->")  # the trace readers' convention (semantics/values.py) and Z3's
    if not (t.startswith("{") and t.endswith("}") and "->" in t):
        return None
    inner = t[1:-1]
    rows: list[list[str]] = []
    default = "?"
    more = 0
    for entry in _split_top(inner):
        if entry.startswith("else"):
            default = decimals(entry.split("->", 1)[1].strip())
            continue
        head, _, body = entry.partition("->")
        head, body = head.strip(), body.strip()
        params = [p.strip() for p in head.strip("()").split(",")]
        if not (body.startswith("(if ") or body.startswith("if ")):
            if all(re.fullmatch(r"p\d+", p) for p in params):  # a constant function (p1, p2) -> v
                default = decimals(body)
            else:
                if len(rows) < max_rows:
                    rows.append([decimals(head), decimals(body)])
                else:
                    more += 1
            continue
        # one linear pass: "(if (C1) then v1 else (if (C2) then v2 else w))"
        i, opened, n = 0, 0, len(body)
        while True:
            while i < n and body[i] == " ":
                i += 1
            if body.startswith("(if ", i):
                i += 1
                opened += 1
            if not body.startswith("if ", i):
                tail = body[i:].rstrip()
                if opened and tail.endswith(")" * opened):
                    tail = tail[:len(tail) - opened]
                default = decimals(tail.strip())
                break
            k = body.index("(", i + 2)
            end = _balanced(body, k)
            cond = body[k:end]
            then_at = body.index(" then ", end)
            else_at = _top_else(body, then_at + 6)
            value = body[then_at + 6:else_at].strip()
            point = _point(cond, params)
            if "*" in point or _has_top_or(cond):
                # a branch that is not one point (a disjunction, a free argument): the branches
                # then say nothing of where the last else applies, so there is no table to show
                return None
            if len(rows) < max_rows:
                rows.append([point, decimals(value)])
            else:
                more += 1
            i = else_at + 6
    return {"rows": rows, "more": more, "else": default}


def _has_top_or(cond: str) -> bool:
    """Does the condition (parenthesised or not) have an ``or`` outside its inner parentheses?"""
    body = cond.strip()
    if body.startswith("(") and _balanced(body, 0) == len(body):
        body = body[1:-1]
    return _top_level(body, " or ") < len(body)


def _top_else(s: str, j: int = 0) -> int:
    """Index of the first `` else `` of ``s`` from ``j`` on, outside parentheses."""
    return _top_level(s, " else ", j)


def _top_level(s: str, word: str, j: int = 0) -> int:
    """Index of the first ``word`` of ``s`` from ``j`` on outside parentheses (``len(s)`` if none)."""
    depth = 0
    while j < len(s):
        c = s[j]
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
        elif depth == 0 and s.startswith(word, j):
            return j
        j += 1
    return len(s)


def _short(text: str) -> str:
    text = decimals(text)
    if len(text) <= MAX_VALUE:
        return text
    return text[:MAX_VALUE].rsplit(" ", 1)[0] + f" ... ({len(text):,} characters in all)"


def counterexample_table(model: Mapping[str, object] | None, default_node: str = "") -> list[CexRow]:
    """The rows of a model: ``{"node", "variable", "value", "table"}`` per
    symbol, ``table`` the finite table of a function value (else ``None``).
    ``Agent.in.wayP`` gives node ``Agent``, variable ``in.wayP``; a name
    without a node part is given ``default_node``.  Values are cut at
    :data:`MAX_VALUE` characters; rationals are decimals where exact."""
    rows: list[CexRow] = []
    for name, value in (model or {}).items():
        node, var = default_node, str(name)
        parts = var.split(".")
        if len(parts) >= 3 and parts[1] in ("in", "out"):
            node, var = parts[0], ".".join(parts[1:])
        text = value if isinstance(value, str) else str(value)
        table = function_table(text)
        if table is not None:
            shown = ", ".join(f"{a} -> {v}" for a, v in table["rows"][:3])
            more = len(table["rows"]) - 3 + table["more"]
            text = "{" + shown + (f", ... {more} more" if more > 0 else "") + (", " if shown else "") + f"else -> {table['else']}" + "}"
        rows.append({"node": node, "variable": var, "value": _short(text), "table": table})
    return rows


def counterexample_rows(model: Mapping[str, object] | None, default_node: str = "") -> list[CexTableRow]:
    """:func:`counterexample_table`'s rows decoded into their record
    (:class:`~rclverify.records.repair_rows.CexTableRow`), for a reader that prints them."""
    return msgspec.convert(counterexample_table(model, default_node), list[CexTableRow])
