"""The launch file's own functions called while a ROS 2 Python launch file
is read (never executed): ``OpaqueFunction(function=f, ...)`` and a call of
a module-level function, evaluated by :mod:`launch_ros2` over the actions
the function returns (:func:`called`), with their parameters bound to the
call's arguments; a function called inside itself, or more than
:data:`MAX_CALLS` deep, is not evaluated.
"""
from __future__ import annotations

import ast
from contextlib import contextmanager
from typing import Iterator

from rclverify.ros.extract.launch_py_values import ENV, TWICE, callee, expand, kw, once
from rclverify.ros.extract.launch_py_flow import flat

MAX_CALLS = 8  # functions of the launch file evaluated inside one another
FUNCS: dict[str, ast.FunctionDef] = {}  # the launch file's module-level functions, while it is read
CALLING: list[str] = []  # the functions being evaluated (a recursion stops)
FN: list[ast.FunctionDef] = []  # the function whose statements are read (innermost last)


@contextmanager
def called(fn: ast.expr | None, call: ast.Call, opaque: bool) -> Iterator[ast.List | ast.Tuple | str]:
    """The list of actions a function of the launch file returns, its parameters bound
    to the call's arguments (``OpaqueFunction(function=f, args=[...],
    kwargs={...})`` calls ``f(context, *args, **kwargs)``) and its own names
    bound once read as in ``generate_launch_description()``, while the block
    reads it (the bindings undone after); of its ``return`` statements, those
    in the branches that run (an ``if`` of known test runs one,
    :mod:`launch_py_flow`); a function with other than one, or returning what
    is not a list of actions, gives why as a string."""
    if not isinstance(fn, ast.Name) or fn.id not in FUNCS:
        yield f"'{ast.unparse(fn) if fn is not None else ''}' is not a function defined in the launch file"
        return
    f = FUNCS[fn.id]
    if fn.id in CALLING or len(CALLING) >= MAX_CALLS:
        yield "it is called inside itself"
        return
    params = [a.arg for a in f.args.posonlyargs + f.args.args]
    given: dict[str, ast.expr] = dict(zip(params[len(params) - len(f.args.defaults):], f.args.defaults))
    pos: list[ast.expr] = list(call.args) if not opaque else []
    named = {k.arg: k.value for k in call.keywords if k.arg} if not opaque else {}
    if opaque:
        more, kwmore = kw(call, "args"), kw(call, "kwargs")
        more, kwmore = expand(more) if more is not None else None, expand(kwmore) if kwmore is not None else None
        pos = list(more.elts) if isinstance(more, (ast.List, ast.Tuple)) else []
        if isinstance(kwmore, ast.Dict):
            named = {k.value: v for k, v in zip(kwmore.keys, kwmore.values)
                     if isinstance(k, ast.Constant) and isinstance(k.value, str)}
        params = params[1:]  # the launch context
    given.update({p: expand(v) for p, v in zip(params, pos)})
    given.update({p: expand(v) for p, v in named.items() if p in params})
    mine, twice = once(list(ast.walk(f)))
    saved, saved_twice = dict(ENV), dict(TWICE)
    CALLING.append(fn.id)
    FN.append(f)
    try:
        for p in params:
            ENV.pop(p, None)
        ENV.update(given)
        ENV.update(mine)
        for k in twice:
            ENV.pop(k, None)
        for k in mine:
            TWICE.pop(k, None)
        TWICE.update(twice)
        # the returns of the statements that run: an if whose test is known runs its branch only
        rets = [r.value for st in flat(f.body, []) for r in ast.walk(st)
                if isinstance(r, ast.Return) and r.value is not None]
        if len(rets) != 1:
            yield f"it has {len(rets)} return statements (which one runs is chosen at run time)" if rets \
                else "it returns no actions"
            return
        ret = expand(rets[0])
        if isinstance(ret, ast.Call) and callee(ret) == "LaunchDescription" and ret.args:
            ret = expand(ret.args[0])
        if not isinstance(ret, (ast.List, ast.Tuple)):
            yield f"it returns '{ast.unparse(rets[0])}', not a list of actions read statically"
            return
        yield ret
    finally:
        CALLING.pop()
        FN.pop()
        ENV.clear()
        ENV.update(saved)
        TWICE.clear()
        TWICE.update(saved_twice)
