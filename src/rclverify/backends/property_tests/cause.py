"""The implementation line a failing example takes (issue 48).

A property-test failure is the implementation's, not the contract's: the
place to look is the line of the implementation that produced the wrong
output (the branch taken), not the guarantee it violates.  The failing
example is run once more under :func:`sys.settrace`, tracing only the
frames of the implementation's own file, and the last line of that file
executed before the call returned (or raised) is the cause: for
``return {"speed": 1.0}`` in the wrong branch, that ``return`` line.

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
    """Run ``call()`` with a tracer on the frames of ``file``; the line number
    of the last line of ``file`` executed (``None`` when none was).  The
    tracer in place before (a coverage tool's) is put back."""
    last: list[int] = []

    def local(frame: FrameType, event: str, arg: Any) -> Any:
        if event in ("line", "return", "exception"):
            last.append(frame.f_lineno)
        return local

    def tracer(frame: FrameType, event: str, arg: Any) -> Any:
        if event == "call" and os.path.abspath(frame.f_code.co_filename) == file:
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
    return last[-1] if last else None


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
