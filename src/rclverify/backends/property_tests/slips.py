"""The implementation line with the slip: the statement whose one-token
correction makes the failing example meet the guarantee.

A wrong output is often passed on by a ``return`` that is itself right
(``return {"ok": ok}`` after ``ok = x < limit``, a slip for ``<=``), so the
line that made the wrong value is found by following the failing example
back through the code, then asking which statement, corrected, gives an
output the contract allows:

1. *The failing run.*  The failing example is replayed under
   :func:`sys.settrace`, recording the lines the implementation's function
   (a class's ``step`` method: every step up to the failing one) executes.
2. *Its data flow.*  From the ``return`` the run ended at, the names it
   reads (locals and ``self.x`` attributes, :mod:`ast`) are followed back
   through the executed statements to the assignment that last set each on
   this run, and from there to the names that assignment read (a dynamic
   backward slice; a local does not outlive its step, an attribute does).
   The candidates are the ``return``, then the slice's assignments, nearest
   the output first, then the branch conditions (``if``, ``while``) the run
   executed, the latest first: a comparison that sent the example down the
   wrong branch made the value too.
3. *The one-token corrections.*  Each candidate's expressions are changed
   one token at a time, as a slip is made (:func:`mutations`): a
   comparison's strictness (``<`` / ``<=``, ``>`` / ``>=``, ``==`` /
   ``!=``), ``+`` / ``-``, ``*`` / ``/``, ``and`` / ``or``, a ``not``
   dropped, a truth value negated, a number moved by one or replaced by a
   number the contract names.  A corrected function is compiled from the
   implementation's own source (its lines kept) in its module's names.
4. *The judgement.*  A correction counts when the failing example then
   meets the guarantee and every neighbour example that met it before
   still does (the neighbours are examples Hypothesis draws from the same
   input space, judged by the harness's own check,
   :mod:`.neighbours`).  Of those, the one that makes the most neighbours
   meet the guarantee is kept, the nearest candidate on a tie; its line is
   the slip's.  A corrected function runs under a budget of lines
   (:data:`LINES_SLACK`): one that exceeds it (a loop that no longer ends)
   fails there.

No correction, a function this cannot recompile (a closure, a decorated
function, a ``step`` defined in another file) or a run that raised: no line
here, and :mod:`.cause` names the statement that computed the output.
"""
from __future__ import annotations

import ast
import copy
import inspect
import sys
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from types import CodeType, FrameType
from typing import Any, Callable, Iterator, Mapping, Sequence

#: Most corrections tried on the failing example per failure (each is a compile and a replay).
MAX_MUTANTS = 160

#: Lines a corrected function may run per example, beyond :data:`LINES_PER_LINE` times the failing run's: a
#: correction that loops for ever (``remaining - STEP`` made ``+``) is stopped and counts as no correction.
LINES_SLACK = 10_000
LINES_PER_LINE = 100

#: ``impl, example -> bool``: does ``impl`` (a function or a class) meet the guarantee on ``example``?
Judge = Callable[[Any, Any], bool]

_CMP: dict[type[ast.cmpop], type[ast.cmpop]] = {
    ast.Lt: ast.LtE, ast.LtE: ast.Lt, ast.Gt: ast.GtE, ast.GtE: ast.Gt, ast.Eq: ast.NotEq, ast.NotEq: ast.Eq}
_ARITH: dict[type[ast.operator], type[ast.operator]] = {ast.Add: ast.Sub, ast.Sub: ast.Add, ast.Mult: ast.Div,
                                                        ast.Div: ast.Mult}


@dataclass(frozen=True)
class Mutation:
    """One one-token correction: the node at ``index`` of :func:`ast.walk`
    over the function's definition replaced by ``new``; ``line`` the
    changed token's line."""

    index: int
    new: ast.AST
    line: int


@dataclass(frozen=True)
class Target:
    """The function a failing example runs: its definition in its file, the
    names it is compiled in, and, for a class, the class (``step`` is the
    function)."""

    fdef: ast.FunctionDef
    file: str
    globals: Mapping[str, Any]
    code: CodeType
    cls: type | None


def target(impl: Any) -> Target | None:
    """The :class:`Target` of ``impl`` (a function, or a class whose
    ``step`` is defined in the class's file); ``None`` when its definition
    cannot be recompiled as it is (a closure, a decorator, no source)."""
    fn = impl.__dict__.get("step") if inspect.isclass(impl) else impl
    code = getattr(fn, "__code__", None)
    if fn is None or code is None or code.co_freevars:
        return None
    try:
        tree = ast.parse(Path(code.co_filename).read_text(encoding="utf-8"), code.co_filename)
    except (OSError, SyntaxError, ValueError):
        return None
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name == code.co_name and node.lineno == code.co_firstlineno \
                and not node.decorator_list:
            return Target(node, code.co_filename, fn.__globals__, code, impl if inspect.isclass(impl) else None)
    return None


def compiled(t: Target, fdef: ast.FunctionDef) -> Any:
    """``fdef`` (``t``'s definition, changed or not) as ``t``'s kind of
    implementation: the function, or a subclass of ``t.cls`` with it as
    ``step``.  Compiled under ``t``'s file name, so its lines are the
    source's; in a copy of the module's names (nothing of the module is
    changed)."""
    code = compile(ast.Module(body=[fdef], type_ignores=[]), t.file, "exec")
    space: dict[str, Any] = {}
    exec(code, dict(t.globals), space)  # noqa: S102 - the implementation's own source, one token changed
    fn = space[fdef.name]
    return type(t.cls.__name__, (t.cls,), {"step": fn}) if t.cls is not None else fn


def executed(t: Target, impl: Any, example: Any, step: int | None) -> list[tuple[int, int]] | None:
    """``[(call, line)]``: the lines of ``t``'s function the failing
    ``example`` executes, per call (0 for a function, the step's index for
    a class, up to the 1-based failing ``step``), ending with the line of
    the ``return`` the last call ended at; ``None`` when the replay raised."""
    events: list[tuple[int, int]] = []
    call = [0]
    ended: list[int] = []

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "line":
            events.append((call[0], frame.f_lineno))
        elif event == "return":
            ended.append(frame.f_lineno)
        return local

    def tracer(frame: FrameType, event: str, arg: Any) -> Any:
        return local if event == "call" and frame.f_code is t.code else None

    before = sys.gettrace()
    sys.settrace(tracer)
    try:
        if t.cls is None:
            impl(**_kwargs(example))
        else:
            steps = list(example)[: step or len(example)]
            machine = impl()
            for k, inputs in enumerate(steps):
                call[0] = k
                machine.step(**_kwargs(inputs))
    except Exception:  # noqa: BLE001 - the implementation's own failure (the harness reported it): no line here
        return None
    finally:
        sys.settrace(before)
    return [*events, (call[0], ended[-1])] if ended else None


def candidates(fdef: ast.FunctionDef, run: Sequence[tuple[int, int]]) -> list[ast.stmt]:
    """The statements that may have made the returned value (module
    docstring, step 2): the ``return`` the run ended at, the assignments of
    its backward slice nearest first, then the executed branch conditions
    latest first.  ``[]`` when the run did not end at a ``return``."""
    at: dict[int, list[ast.stmt]] = {}
    for node in ast.walk(fdef):
        if isinstance(node, ast.stmt) and node is not fdef:
            at.setdefault(node.lineno, []).append(node)
    ret = [s for s in at.get(run[-1][1], []) if isinstance(s, ast.Return)]
    if not ret:
        return []
    me = fdef.args.args[0].arg if fdef.args.args else "self"
    needed = _reads(ret[0].value, me)
    sliced: list[ast.stmt] = [ret[0]]
    branches: list[ast.stmt] = []
    call = run[-1][0]
    for k, line in reversed(run[:-1]):
        if k != call:  # an earlier step: its locals are gone, its attributes are not
            needed = {n for n in needed if n.startswith(f"{me}.")}
            call = k
        for s in reversed(at.get(line, [])):
            if isinstance(s, (ast.If, ast.While)):
                if s not in branches:
                    branches.append(s)
                continue
            defs, reads = _defines(s, me)
            if defs & needed:
                if s not in sliced:
                    sliced.append(s)
                needed = (needed - defs) | reads
    return sliced + branches


def mutations(fdef: ast.FunctionDef, stmt: ast.stmt, numbers: Sequence[Fraction]) -> Iterator[Mutation]:
    """The one-token corrections of ``stmt``'s own expressions (not of the
    statements nested in it), in source order (module docstring, step 3)."""
    index = {id(n): i for i, n in enumerate(ast.walk(fdef))}
    for root in _expressions(stmt):
        for node in ast.walk(root):
            for new in _changed(node, numbers):
                new = ast.copy_location(copy.deepcopy(new), node)  # the function's own nodes stay as they are
                yield Mutation(index[id(node)], ast.fix_missing_locations(new),
                               getattr(node, "lineno", stmt.lineno))


def slip_line(impl: Any, example: Any, step: int | None, numbers: Sequence[Fraction], judge: Judge,
              draw: Callable[[], Sequence[tuple[Any, bool]]]) -> int | None:
    """The line of the slip that makes the failing ``example`` (a
    function's inputs ``{"in.x": value}``, a class's steps with ``step`` the
    1-based failing one) violate the guarantee (module docstring); ``None``
    when no one-token correction does it.  ``numbers`` the numbers the
    contract names; ``judge(impl, example)`` the harness's check;
    ``draw()`` the neighbours, ``[(example, met the guarantee)]`` drawn from
    the same input space (called once, only when a correction can be
    tried)."""
    t = target(impl)
    if t is None:
        return None
    failing = list(example)[: step or len(example)] if t.cls is not None else example
    try:
        if judge(compiled(t, t.fdef), failing):  # the recompiled source must fail as the implementation does
            return None
    except Exception:  # noqa: BLE001 - source that does not compile on its own: no line here
        return None
    run = executed(t, impl, failing, step)
    if run is None:
        return None
    neighbours = draw()
    kept = [ex for ex, ok in neighbours if ok]
    budget = LINES_PER_LINE * len(run) + LINES_SLACK

    def met(fixed: Any, ex: Any) -> bool:
        return _bounded(lambda: judge(fixed, ex), t.file, budget)
    best: tuple[int, int] | None = None  # (neighbours met, line)
    tried = 0
    for stmt in candidates(t.fdef, run):
        for m in mutations(t.fdef, stmt, numbers):
            if tried >= MAX_MUTANTS:
                return best[1] if best else None
            tried += 1
            fixed = _apply(t, m)
            if fixed is None or not met(fixed, failing) or not all(met(fixed, ex) for ex in kept):
                continue
            score = sum(1 for ex, ok in neighbours if ok or met(fixed, ex))
            if best is None or score > best[0]:
                best = (score, m.line)
            if score == len(neighbours):  # every neighbour met: nothing later can do better
                return best[1]
    return best[1] if best else None


class _OutOfLines(Exception):
    """A corrected function ran more lines than its budget."""


def _bounded(call: Callable[[], bool], file: str, budget: int) -> bool:
    """``call()`` with every frame of ``file`` stopped by :class:`_OutOfLines`
    after ``budget`` lines in all (the judge counts that as a failure);
    the tracer in place before is put back."""
    left = [budget]

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "line":
            left[0] -= 1
            if left[0] < 0:
                raise _OutOfLines(f"more than {budget} lines")
        return local

    def tracer(frame: FrameType, event: str, arg: Any) -> Any:
        return local if event == "call" and frame.f_code.co_filename == file else None

    before = sys.gettrace()
    sys.settrace(tracer)
    try:
        return call()
    except _OutOfLines:
        return False
    finally:
        sys.settrace(before)


def _apply(t: Target, m: Mutation) -> Any:
    fdef = copy.deepcopy(t.fdef)
    old = list(ast.walk(fdef))[m.index]

    class Swap(ast.NodeTransformer):
        def visit(self, node: ast.AST) -> Any:
            return copy.deepcopy(m.new) if node is old else super().visit(node)
    try:
        return compiled(t, Swap().visit(fdef))
    except Exception:  # noqa: BLE001 - a change that does not compile is no correction
        return None


def _changed(node: ast.AST, numbers: Sequence[Fraction]) -> list[ast.AST]:
    """The one-token changes of ``node`` itself (module docstring, step 3)."""
    out: list[ast.AST] = []
    if isinstance(node, ast.Compare):
        for i, op in enumerate(node.ops):
            if type(op) in _CMP:
                ops = [*node.ops[:i], _CMP[type(op)](), *node.ops[i + 1:]]
                out.append(ast.Compare(node.left, ops, node.comparators))
    elif isinstance(node, ast.BinOp) and type(node.op) in _ARITH:
        out.append(ast.BinOp(node.left, _ARITH[type(node.op)](), node.right))
    elif isinstance(node, ast.BoolOp):
        out.append(ast.BoolOp(ast.Or() if isinstance(node.op, ast.And) else ast.And(), node.values))
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        out.append(node.operand)
    elif isinstance(node, ast.Constant) and isinstance(node.value, bool):
        out.append(ast.Constant(not node.value))
    elif isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        v = node.value
        seen = {Fraction(v)}
        for c in (Fraction(v) - 1, Fraction(v) + 1, *numbers):
            if c in seen or (isinstance(v, int) and c.denominator != 1):
                continue
            seen.add(c)
            out.append(ast.Constant(int(c) if isinstance(v, int) else float(c)))
    return out


def _expressions(stmt: ast.stmt) -> list[ast.expr]:
    if isinstance(stmt, (ast.Return, ast.Assign, ast.AugAssign, ast.AnnAssign)):
        return [stmt.value] if stmt.value is not None else []
    if isinstance(stmt, (ast.If, ast.While)):
        return [stmt.test]
    return []


def _reads(e: ast.AST | None, me: str) -> set[str]:
    """The locals and ``me.x`` attributes ``e`` reads."""
    out: set[str] = set()
    for n in ast.walk(e) if e is not None else ():
        if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id == me:
            out.add(f"{me}.{n.attr}")
        elif isinstance(n, ast.Name) and n.id != me:
            out.add(n.id)
    return out


def _defines(s: ast.stmt, me: str) -> tuple[set[str], set[str]]:
    """``(defined, read)``: what statement ``s`` sets (a local, an ``me.x``
    attribute; a container it stores into is set and read) and what it
    reads to do so."""
    targets: list[ast.expr] = []
    reads: set[str] = set()
    if isinstance(s, ast.Assign):
        targets = list(s.targets)
    elif isinstance(s, (ast.AugAssign, ast.AnnAssign)):
        targets = [s.target]
    elif isinstance(s, ast.For):
        targets, reads = [s.target], _reads(s.iter, me)
    else:
        return set(), set()
    if isinstance(s, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
        reads = _reads(s.value, me)
    defs: set[str] = set()
    for tgt in targets:
        for n in ast.walk(tgt):
            if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
                defs.add(n.id)
            elif isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store) and isinstance(n.value, ast.Name):
                defs.add(f"{me}.{n.attr}" if n.value.id == me else n.value.id)
            elif isinstance(n, ast.Subscript) and isinstance(n.ctx, ast.Store):
                base = _reads(n.value, me)
                defs |= base
                reads |= base | _reads(n.slice, me)
    if isinstance(s, ast.AugAssign):
        reads |= defs
    return defs, reads


def _kwargs(inputs: Mapping[str, object]) -> dict[str, object]:
    return {k.removeprefix("in."): v for k, v in inputs.items()}
