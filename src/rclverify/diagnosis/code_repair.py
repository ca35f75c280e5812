"""Checked repairs of a failing property test whose culprit is a line of the
implementation (docs/diagnosis.md, "Repairs of the implementation").

The property-tests backend names the implementation line where a failing
example goes wrong (``counterexample.cause``: the line whose one-token
correction makes the example meet the guarantee, else the line that
computed the output; backends/property_tests/slips.py and cause.py).  Here
the one-token corrections of that line are offered as repairs, each kept
only when it was checked:

1. *The candidates* (:func:`candidate_edits`): the corrections the culprit
   search tries on the statement at that line (a comparison's strictness,
   ``+``/``-``, ``*``/``/``, ``and``/``or``, a ``not`` dropped, a truth
   value negated, a number moved by one or replaced by a number the
   contract names: :func:`~rclverify.backends.property_tests.slips.mutations`),
   and ``max``/``min`` swapped, each as a text edit of that line's
   expression cut to the characters that change; then an integer replaced
   by a non-integer number the contract names, an operand replaced by
   another name of the function, a slice dropped (:func:`_operands`), and
   last a guard against a zero divisor inserted before the statement
   (:func:`_guards`).  Ordered by class (an
   operator or a name first, then a number moved by one, then a number the
   contract names: :func:`_rank`), then smallest (the characters taken out
   and put in), then in source order.
2. *The check* (:func:`~rclverify.diagnosis.code_repair_check.checked_repairs`): the implementation's import
   closure and the files the mapping reads are copied to a scratch folder,
   the edit is made there (the workspace is never touched), and every
   guarantee of the node is run again by the backend's own harness
   (:func:`~rclverify.backends.property_tests.harness.run_guarantee`, the
   plan entry's seed and budget), the failing guarantee first.  A
   candidate is kept when every run is ``discharged``: an edit that
   repairs the failing guarantee and breaks another is not offered.
3. At most :data:`MAX_REPAIRS` are kept, of at most :data:`MAX_TRIED`
   candidates tried.
4. *Around the line* (:func:`around_lines`): when no candidate of the
   culprit line passes, the one-token corrections of the other statements
   of the same function are tried the same way, the nearest line first (an
   earlier line before a later one at the same distance: a value is
   computed before it is returned), at most :data:`MAX_AROUND` of them.  A
   wrong value made on one line and returned on another (``worst =
   min(...)`` then ``return {"ok": worst <= LIMIT}``), or a wrong branch
   whose taken ``return`` was named, is repaired where it was made.
5. *Two tokens* (:mod:`.pair_edits`): when nothing of 1-4 passes, two of
   the culprit line's one-token corrections made together, checked the
   same way.

What the check shows is what the harness shows: the node's guarantees
held on every example Hypothesis drew from the edited copy; not that the
edit is the right one for the robot, nor any proof.  Nothing here raises
for the user's code: a candidate whose run raises is not kept.
"""
from __future__ import annotations

import ast
from fractions import Fraction
from typing import Any, Iterable, Mapping, Sequence

from rclverify.diagnosis.edits import Edit

#: Most repairs offered for one failure.
MAX_REPAIRS = 3
#: Most candidates run on a scratch copy for one failure (each runs every guarantee of the node).
MAX_TRIED = 12
#: Most candidates tried around the culprit line (step 4) when none of the line passes.
MAX_AROUND = 12
#: The swapped names of a call: ``max`` for ``min`` and back.
_SWAP = {"max": "min", "min": "max"}


def _col(line_text: str, byte_offset: int) -> int:
    """The 1-based character column of ``byte_offset`` (ast's UTF-8 offset) in ``line_text``."""
    return len(line_text.encode("utf-8")[:byte_offset].decode("utf-8", errors="ignore")) + 1


def _edit(file: str, lines: list[str], node: ast.AST, new: str) -> Edit | None:
    """The edit putting ``new`` in place of ``node``'s text, cut to the characters that change; ``None``
    when nothing changes or ``node`` has no span."""
    line, end_line = getattr(node, "lineno", None), getattr(node, "end_lineno", None)
    col, end_col = getattr(node, "col_offset", None), getattr(node, "end_col_offset", None)
    if line is None or end_line is None or col is None or end_col is None:
        return None
    a, b = _col(lines[line - 1], col), _col(lines[end_line - 1], end_col)
    old = Edit(file, line, a, end_line, b, "").deleted("".join(lines))
    if old == new:
        return None
    p = 0  # the common prefix and suffix left as they are
    while p < min(len(old), len(new)) and old[p] == new[p]:
        p += 1
    s = 0
    while s < min(len(old), len(new)) - p and old[-1 - s] == new[-1 - s]:
        s += 1
    while 0 < p and _joined(old[p - 1], old[p:p + 1] or new[p:p + 1]) or 0 < p and _joined(old[p - 1], new[p:p + 1]):
        p -= 1  # a token is changed whole: ``<`` for ``<=``, ``max`` for ``min``
    while 0 < s and (_joined(old[len(old) - s], old[len(old) - s - 1:len(old) - s])
                     or _joined(new[len(new) - s], new[len(new) - s - 1:len(new) - s])):
        s -= 1
    start_line, start_col = line, a
    for ch in old[:p]:
        start_line, start_col = (start_line + 1, 1) if ch == "\n" else (start_line, start_col + 1)
    stop_line, stop_col = start_line, start_col
    for ch in old[p:len(old) - s]:
        stop_line, stop_col = (stop_line + 1, 1) if ch == "\n" else (stop_line, stop_col + 1)
    return Edit(file, start_line, start_col, stop_line, stop_col, new[p:len(new) - s])


def _kind(c: str) -> str:
    """A character's token class: ``w`` (a name or number), ``o`` (an operator), ``""`` (anything else)."""
    return "w" if c.isalnum() or c == "_" else "o" if c in "<>=!+-*/%&|^~" else ""


def _joined(a: str, b: str) -> bool:
    """Whether characters ``a`` and ``b`` (``b`` may be empty) belong to one token."""
    return bool(b) and _kind(a) != "" and _kind(a) == _kind(b)


def candidate_edits(source: str, file: str, line: int, numbers: Sequence[Fraction],
                    kinds: Mapping[str, str] | None = None) -> list[Edit]:
    """The one-token corrections of the statement at ``line`` of ``source`` (the implementation file
    ``file``, as the plan names it) inside a function (module docstring, step 1), each once, smallest
    first; ``[]`` when the line holds no statement of a function or the file does not parse.
    ``kinds``: a name of the contract's inputs and outputs -> its type and unit (:func:`contract_kinds`):
    a name is never put for one of another type or unit (a speed for a distance)."""
    from rclverify.backends.property_tests.slips import mutations  # deferred: start-up (the backend's search)
    try:
        tree = ast.parse(source, file)
    except (SyntaxError, ValueError):
        return []
    lines = source.splitlines(keepends=True)
    out: list[Edit] = []
    named: list[Edit] = []  # class 2 (:func:`_rank`): an integer replaced by a number the contract names
    other: list[Edit] = []  # class 3: an operand put for another, a slice dropped
    guards: list[Edit] = []  # class 4: a guard against a zero divisor
    for fdef in (n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))):
        if not fdef.lineno <= line <= (fdef.end_lineno or fdef.lineno) or not isinstance(fdef, ast.FunctionDef):
            continue
        stmts = [s for s in ast.walk(fdef) if isinstance(s, ast.stmt) and s is not fdef and s.lineno == line
                 and not isinstance(s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))]
        nodes = list(ast.walk(fdef))
        for stmt in stmts:
            for m in mutations(fdef, stmt, numbers):
                old = nodes[m.index]
                if getattr(old, "lineno", None) == line:
                    out.append(_edit(file, lines, old, ast.unparse(m.new)) or _NONE)
            for call in _calls(stmt):
                assert isinstance(call.func, ast.Name)
                out.append(_edit(file, lines, call.func, _SWAP[call.func.id]) or _NONE)
            for node, new in _operands(fdef, stmt, numbers, kinds or {}):
                (named if new[:1].isdigit() else other).append(_edit(file, lines, node, new) or _NONE)
            guards.extend(_guards(fdef, stmt, file, lines))
    seen: set[tuple[int, int, int, int, str]] = set()
    kept: list[tuple[int, Edit]] = []
    for cls, e in [*((-1, e) for e in out), *((2, e) for e in named), *((3, e) for e in other),
                   *((4, e) for e in guards)]:
        key = (e.line, e.col, e.end_line, e.end_col, e.text)
        if e is not _NONE and key not in seen:
            seen.add(key)
            kept.append((cls if cls >= 0 else _rank(e.deleted(source), e.text), e))
    return [e for _, e in sorted(kept, key=lambda ce: (ce[0], len(ce[1].deleted(source)) + len(ce[1].text),
                                                       ce[1].line, ce[1].col))]


def _guards(fdef: ast.FunctionDef, stmt: ast.stmt, file: str, lines: list[str]) -> list[Edit]:
    """A guard inserted before ``stmt`` for each divisor of its own expressions that is a name
    (``count / dt``): ``if dt == 0:`` returning zero for every output (``0.0``, ``0`` or ``False`` as the
    function's other returns have it), when every ``return`` of the function is a dict with the same keys;
    ``[]`` otherwise.  The insertion is an edit of no characters at ``stmt``'s first column."""
    roots = [stmt.value] if isinstance(stmt, (ast.Return, ast.Assign, ast.AugAssign, ast.AnnAssign)) \
        and stmt.value is not None else []
    divisors = list(dict.fromkeys(n.right.id for r in roots for n in ast.walk(r) if isinstance(n, ast.BinOp)
                                  and isinstance(n.op, (ast.Div, ast.FloorDiv, ast.Mod))
                                  and isinstance(n.right, ast.Name)))
    rets = [n.value for n in ast.walk(fdef) if isinstance(n, ast.Return)]
    dicts = [r for r in rets if isinstance(r, ast.Dict)]
    if not divisors or not rets or len(dicts) != len(rets) or any(k is None for r in dicts for k in r.keys):
        return []
    keys = [ast.unparse(k) for k in dicts[0].keys if k is not None]
    if any([ast.unparse(k) for k in r.keys if k is not None] != keys for r in dicts):
        return []
    zero: dict[str, str] = {k: "0.0" for k in keys}
    for r in dicts:
        for k, v in zip(r.keys, r.values):
            if k is not None and isinstance(v, ast.Constant) and type(v.value) in (bool, int):
                zero[ast.unparse(k)] = "False" if type(v.value) is bool else "0"
    indent = lines[stmt.lineno - 1][:stmt.col_offset]
    body = ", ".join(f"{k}: {zero[k]}" for k in keys)
    return [Edit(file, stmt.lineno, 1, stmt.lineno, 1, f"{indent}if {d} == 0:\n{indent}    return {{{body}}}\n")
            for d in divisors]


def contract_kinds(node: Any) -> dict[str, str]:
    """Each input's and output's name of the checked contract ``node`` -> its type and declared unit
    (``"REAL [m]"``; an input's where a name is both), for :func:`candidate_edits`."""
    out: dict[str, str] = {}
    for prefix, table in (("out", node.outputs), ("in", node.inputs)):
        for name, typ in table.items():
            unit = node.unit_of(prefix, name)
            out[name] = f"{typ} {unit}" if unit is not None else str(typ)
    return out


def _operands(fdef: ast.FunctionDef, stmt: ast.stmt, numbers: Sequence[Fraction],
              kinds: Mapping[str, str]) -> Iterable[tuple[ast.AST, str]]:
    """The one-token corrections of ``stmt``'s own expressions on its first line that the culprit search
    does not make: an integer replaced by a number the contract names that is not one (``273`` for
    ``273.15``), a name or a truth value replaced by another name the function reads as a parameter or
    assigns (``final = distance`` for ``final = remaining``, ``True`` for the input ``engage``), and a
    slice dropped (``ranges[:-1]`` for ``ranges``); each as ``(node, its new text)``."""
    roots: list[ast.AST] = []
    if isinstance(stmt, (ast.Return, ast.Assign, ast.AugAssign, ast.AnnAssign)) and stmt.value is not None:
        roots = [stmt.value]
    elif isinstance(stmt, (ast.If, ast.While)):
        roots = [stmt.test]
    params = [a.arg for a in (*fdef.args.posonlyargs, *fdef.args.args, *fdef.args.kwonlyargs)]
    stored = [n.id for n in ast.walk(fdef) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)]
    own = {n.id for n in ast.walk(stmt) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    names = [x for x in dict.fromkeys([*params, *stored]) if x not in own]
    called = {id(n.func) for r in roots for n in ast.walk(r) if isinstance(n, ast.Call)}
    for r in roots:
        for n in ast.walk(r):
            if getattr(n, "lineno", None) != stmt.lineno:
                continue
            if isinstance(n, ast.Constant) and type(n.value) is int:
                yield from ((n, repr(float(c))) for c in numbers if c.denominator != 1)
            elif isinstance(n, ast.Constant) and isinstance(n.value, bool) or \
                    isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load) and id(n) not in called:
                was = kinds.get(getattr(n, "id", ""))  # a contract variable's kind: only a name of that kind
                yield from ((n, x) for x in names if x != getattr(n, "id", None)
                            and (was is None or kinds.get(x, was) == was))
            elif isinstance(n, ast.Subscript) and isinstance(n.slice, ast.Slice):
                yield n, ast.unparse(n.value)


def around_lines(source: str, line: int) -> list[int]:
    """The lines of the other statements of the function holding ``line`` in ``source`` (not of a nested
    function, not its docstring), nearest ``line`` first, an earlier line first at the same distance;
    ``[]`` when ``line`` is in no function or the file does not parse."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return []
    fdefs = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)
             and n.lineno <= line <= (n.end_lineno or n.lineno)]
    if not fdefs:
        return []
    fdef = max(fdefs, key=lambda n: n.lineno)  # the innermost
    lines: set[int] = set()
    todo: list[ast.stmt] = list(fdef.body)
    while todo:
        s = todo.pop()
        if isinstance(s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant)):
            lines.add(s.lineno)
        todo.extend(c for c in ast.iter_child_nodes(s) if isinstance(c, ast.stmt))
    lines.discard(line)
    return sorted(lines, key=lambda k: (abs(k - line), k > line, k))


def _rank(old: str, new: str) -> int:
    """The class of a one-token correction, tried in this order: 0 an operator or a name (a comparison's
    strictness, ``and``/``or``, ``+``/``-``, ``max``/``min``, a ``not`` dropped, a truth value), 1 a number
    moved by one, 2 a number replaced by another the contract names; :func:`candidate_edits` puts an
    operand replaced by another name and a slice dropped (:func:`_operands`) after them, class 3, and a
    guard against a zero divisor (:func:`_guards`) last, class 4."""
    try:
        a, b = Fraction(old), Fraction(new)
    except (ValueError, ZeroDivisionError):
        return 0
    return 1 if abs(a - b) == 1 else 2


#: No edit (a mutation that changes no character).
_NONE = Edit("", 0, 0, 0, 0, "")


def _calls(stmt: ast.stmt) -> Iterable[ast.Call]:
    """The ``max``/``min`` calls of ``stmt``'s own expressions on its first line."""
    roots: list[ast.AST] = []
    if isinstance(stmt, (ast.Return, ast.Assign, ast.AugAssign, ast.AnnAssign)) and stmt.value is not None:
        roots = [stmt.value]
    elif isinstance(stmt, (ast.If, ast.While)):
        roots = [stmt.test]
    for r in roots:
        for n in ast.walk(r):
            if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id in _SWAP \
                    and n.func.lineno == stmt.lineno:
                yield n


__all__ = ["MAX_AROUND", "MAX_REPAIRS", "MAX_TRIED", "around_lines", "candidate_edits", "contract_kinds"]
