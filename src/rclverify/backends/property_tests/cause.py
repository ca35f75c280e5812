"""The implementation line that computed a failing example's output.

A property-test failure is the implementation's, not the contract's: the
place to look is the line of the implementation that produced the wrong
output, not the guarantee it violates.  The line with the slip
(:mod:`.slips`) is named first; this module's line is named when no
one-token correction makes the example meet the guarantee.  The failing
example is run once more under :func:`sys.settrace`, tracing only the
frames of the implementation's own file.  The cause is the statement that
computed the value returned: the tracer follows the entry
frame's bytecode (``f_trace_opcodes``) and records the line of each store
of a local variable, and the line that last assigned a local the ``return``
statement reads and the returned output
carries (the same object, e.g. ``joint = index + 1`` for ``return
{"joint": joint}``) is named.  When the output carries no local (``return
{"speed": 1.0}`` in the wrong branch), or the call raised, it is the last
line of that file executed: that ``return`` line.

The run is a replay of a shrunk example the harness already ran: the
implementation is pure for a function, and a class is replayed from a new
instance over the example's steps up to the failing one (only the last
traced).  Any exception of the replay is the implementation's and is
ignored here (the harness reported it already).
"""
from __future__ import annotations

import inspect
import os
import sys
from types import FrameType
from typing import Any, Callable, Mapping, Sequence, cast
import dis
import linecache


def implementation_file(impl: Any) -> str | None:
    """The source file of ``impl`` (a function or a class), as its code objects name it; ``None`` when unknown."""
    code = getattr(impl, "__code__", None)
    if code is not None:
        filename: str = code.co_filename
        return os.path.abspath(filename)
    try:
        f = inspect.getsourcefile(impl)
    except TypeError:
        return None
    return os.path.abspath(f) if f else None


def last_line(call: Callable[[], Any], file: str) -> int | None:
    """Run ``call()`` with a tracer on the frames of ``file``; the line of
    ``file`` that computed the value the call returned (module docstring:
    the statement that last assigned a local variable whose value the
    returned output carries), else the last line of ``file`` executed
    (``None`` when none was).  The tracer in place before (a coverage
    tool's) is put back."""
    last: list[int] = []
    outer: list[FrameType] = []  # the first frame of file: the implementation's entry (its return is the output)
    stores: dict[int, str] = {}  # bytecode offset of the entry frame -> the local it stores
    assigned: dict[str, int] = {}  # local of the entry frame -> line that last stored it
    returned: list[Any] = []
    names: set[str] = set()  # the names the return statement reads (empty: any local)

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "opcode" and frame is outer[0] and frame.f_lasti in stores:
            assigned[stores[frame.f_lasti]] = frame.f_lineno  # a store about to run (a local's new value)
        if event in ("line", "return", "exception"):
            last.append(frame.f_lineno)
        if event == "return" and frame is outer[0]:
            returned.append(arg)
            names.update(_returned_names(frame.f_code.co_filename, frame.f_lineno))
        return local

    def tracer(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "call" and os.path.abspath(frame.f_code.co_filename) == file:
            if not outer:
                outer.append(frame)
                stores.update(_stores(frame.f_code))
                frame.f_trace_opcodes = True
            return local
        return None

    before = sys.gettrace()
    sys.settrace(tracer)
    try:
        call()
    except Exception:  # noqa: BLE001 - the implementation's own failure, reported by the harness
        pass
    finally:
        sys.settrace(before)
    final = {k: v for k, v in outer[0].f_locals.items() if not names or k in names} if outer else {}
    computed = _computing_line(returned[0], assigned, final) if returned and outer else None
    return computed or (last[-1] if last else None)


def _stores(code: Any) -> dict[int, str]:
    """``{bytecode offset: local name}`` of every instruction of ``code``
    that stores a local variable (:mod:`dis`): which line assigned a local
    is then known exactly, even when the new value is the same object as
    the old one (a small int)."""
    return {i.offset: str(i.argval) for i in dis.get_instructions(code)
            if i.opname in ("STORE_FAST", "STORE_NAME", "STORE_DEREF", "STORE_GLOBAL")}


def _returned_names(file: str, line: int) -> set[str]:
    """The names the ``return`` statement at ``file``:``line`` reads (a
    small int is one object wherever it is computed, so a local is a
    candidate only when the return reads it); empty when the line is not a
    whole ``return`` statement (one spread over lines: every local is a
    candidate)."""
    import ast  # deferred: start-up (loads ast only when called)
    text = linecache.getline(file, line).strip()
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return set()
    if not tree.body or not isinstance(tree.body[0], ast.Return):
        return set()
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}


def _leaves(value: Any) -> list[Any]:
    """The output values a returned value carries: a mapping's values, a
    sequence's items, an object's attributes, recursively (depth 3)."""
    out: list[Any] = []
    todo = [(value, 0)]
    while todo:
        v, depth = todo.pop()
        out.append(v)
        if depth >= 3:
            continue
        kids = (list(v.values()) if isinstance(v, Mapping) else list(v) if isinstance(v, (list, tuple))
                else list(vars(v).values()) if hasattr(v, "__dict__") and not callable(v) else [])
        todo += [(k, depth + 1) for k in kids]
    return out


def _computing_line(value: Any, assigned: Mapping[str, int], final: Mapping[str, object]) -> int | None:
    """The line that last assigned a local (``assigned``: name -> line,
    ``final``: the locals at the return) whose value is one the returned
    ``value`` carries (the same object; a bare constant is no evidence);
    the latest such line, ``None`` when no local is returned."""
    leaves = [v for v in _leaves(value) if v is not None and not isinstance(v, bool)]
    lines = [assigned[k] for k, v in final.items() if k in assigned and any(v is x for x in leaves)]
    return max(lines) if lines else None


def cause_line(impl: Any, example: Mapping[str, object] | Sequence[Mapping[str, object]], step: int | None,
               shown_file: str) -> str | None:
    """``"<shown_file>:<line>"``: the implementation line the failing
    ``example`` takes last (module docstring), ``None`` when it cannot be
    told (no source file, no line of it executed).  ``impl`` a function
    (``example`` its inputs, ``{"in.x": value}``) or a class (``example``
    the steps, ``step`` the 1-based failing one); ``shown_file`` the
    implementation's path as the plan names it (workspace-relative)."""
    file = implementation_file(impl)
    if file is None:
        return None
    if inspect.isclass(impl):
        runs = cast("Sequence[Mapping[str, object]]", example)  # a class's example is its steps
        steps = list(runs)[: step or len(list(runs))]
        if not steps:
            return None
        machine: Any = impl()
        for inputs in steps[:-1]:
            try:
                machine.step(**_kwargs(inputs))
            except Exception:  # noqa: BLE001 - as the harness ran it
                return None
        line = last_line(lambda: machine.step(**_kwargs(steps[-1])), file)
    else:
        inputs = cast("Mapping[str, object]", example)  # a function's example is its inputs
        line = last_line(lambda: impl(**_kwargs(inputs)), file)
    return f"{shown_file}:{line}" if line is not None else None


def _kwargs(inputs: Mapping[str, object]) -> dict[str, object]:
    return {k.removeprefix("in."): v for k, v in inputs.items()}
