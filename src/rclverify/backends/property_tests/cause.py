"""The implementation line a failing example takes (issue 48).

A property-test failure is the implementation's, not the contract's: the
place to look is the line of the implementation that produced the wrong
output (the branch taken), not the guarantee it violates.  The failing
example is run once more under :func:`sys.settrace`, tracing only the
frames of the implementation's own file.  The cause is the statement that
computed the value returned (issue 64): the tracer records, line by line,
which local variable of the implementation's entry frame each executed line
changed, and the line that last assigned a local the returned output
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
from typing import Any, Callable, Mapping, Sequence


def implementation_file(impl: Any) -> str | None:
    """The source file of ``impl`` (a function or a class), as its code objects name it; ``None`` when unknown."""
    code = getattr(impl, "__code__", None)
    if code is not None:
        return os.path.abspath(code.co_filename)
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
    seen: dict[int, tuple[int, dict[str, Any]]] = {}  # id(frame) -> (line running, locals before it)
    assigned: dict[str, int] = {}  # local of the entry frame -> line that last changed it
    returned: list[Any] = []

    def changes(frame: FrameType) -> None:
        line, before = seen.get(id(frame), (0, {}))
        now = dict(frame.f_locals)
        if frame is outer[0] and line:
            for k, v in now.items():
                if k not in before or before[k] is not v:
                    assigned[k] = line
        seen[id(frame)] = (frame.f_lineno, now)

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        if event in ("line", "return", "exception"):
            last.append(frame.f_lineno)
            changes(frame)
        if event == "return" and frame is outer[0]:
            returned.append(arg)
        return local

    def tracer(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "call" and os.path.abspath(frame.f_code.co_filename) == file:
            if not outer:
                outer.append(frame)
            seen[id(frame)] = (0, dict(frame.f_locals))
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
    computed = _computing_line(returned[0], assigned, outer[0].f_locals) if returned and outer else None
    return computed or (last[-1] if last else None)


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


def _computing_line(value: Any, assigned: Mapping[str, int], final: Mapping[str, Any]) -> int | None:
    """The line that last assigned a local (``assigned``: name -> line,
    ``final``: the locals at the return) whose value is one the returned
    ``value`` carries (the same object; a bare constant is no evidence);
    the latest such line, ``None`` when no local is returned."""
    leaves = [v for v in _leaves(value) if v is not None and not isinstance(v, bool)]
    lines = [assigned[k] for k, v in final.items() if k in assigned and any(v is x for x in leaves)]
    return max(lines) if lines else None


def cause_line(impl: Any, example: Mapping[str, Any] | Sequence[Mapping[str, Any]], step: int | None,
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
        steps = list(example)[: step or len(list(example))]  # type: ignore[arg-type]
        if not steps:
            return None
        machine = impl()
        for inputs in steps[:-1]:
            try:
                machine.step(**_kwargs(inputs))
            except Exception:  # noqa: BLE001 - as the harness ran it
                return None
        line = last_line(lambda: machine.step(**_kwargs(steps[-1])), file)
    else:
        line = last_line(lambda: impl(**_kwargs(example)), file)  # type: ignore[arg-type]
    return f"{shown_file}:{line}" if line is not None else None


def _kwargs(inputs: Mapping[str, Any]) -> dict[str, Any]:
    return {k.removeprefix("in."): v for k, v in inputs.items()}
