"""The statements of a ROS 2 Python launch function in the order Python runs
them, read from its syntax tree (never executed): which branch of an ``if``
runs, the list of actions a variable holds once grown, the actions
``ld.add_action(x)`` adds.

* an ``if`` whose test is known from the file and the scanning environment
  runs its branch (:func:`test`): a comparison ``a == b`` / ``a != b`` of two
  known strings, a known string (true when not empty), ``not``, ``and``,
  ``or``; a string is known when it is a literal, an
  ``EnvironmentVariable('X', default_value=d)`` (``X`` from the environment,
  else ``d``; as launch's ``EnvironmentVariable.perform``), ``x.perform(ctx)``
  of one, ``os.environ.get('X', d)`` / ``os.getenv('X', d)``, or one of those
  with ``.strip(chars)`` / ``.lower()`` / ``.upper()``; a
  ``LaunchConfiguration`` is not known here (its value comes with the
  launch arguments, later);
* an ``if`` whose test is not known keeps both branches, and the caller says
  so (:func:`flat`);
* a list of actions bound once and then grown in order (``nodes.append(x)``,
  ``nodes.extend([...])``, ``nodes += [...]``), also inside the branch an
  ``if`` of known test runs, is the list it holds at the end (:func:`grown`);
  grown inside a loop or an ``if`` not known, it is chosen at run time.

Source: Python's ``if`` statement (The Python Language Reference, 8.1);
launch's ``EnvironmentVariable`` substitution (``launch.substitutions``).
"""
from __future__ import annotations

import ast
import os
import re

from rclverify.ros.extract.launch_py_values import Unres, arg, callee, expand, value

_GROW = ("append", "extend", "insert")
_ENV = re.compile(r"\$\((optenv|env) (\S+)((?: [^)]*)?)\)")


def _text(e: ast.expr) -> str | None:
    """The string ``e`` holds when the file and the environment say it, else ``None``."""
    if isinstance(e, ast.Call) and isinstance(e.func, ast.Attribute):
        name, base = e.func.attr, e.func.value
        if name in ("strip", "lower", "upper", "rstrip", "lstrip"):
            inner = _text(base)
            chars = _text(e.args[0]) if e.args else None
            if inner is None or (e.args and chars is None):
                return None
            return inner.lower() if name == "lower" else inner.upper() if name == "upper" else \
                getattr(inner, name)(chars)
        if name in ("get", "getenv") and ast.unparse(base) in ("os.environ", "os"):
            key, d = arg(e, 0, "key"), arg(e, 1, "default")
            k = _text(key) if key is not None else None
            dv = _text(d) if d is not None else None
            if k is None or (d is not None and dv is None):
                return None
            got = os.environ.get(k, dv)
            return got
    try:
        s = value(expand(e))
    except Unres:
        return None

    def env(m: re.Match[str]) -> str:
        got = os.environ.get(m.group(2))
        if got is None and m.group(1) == "env":
            raise Unres(m.group(0))
        return got if got is not None else m.group(3).strip()

    try:
        s = _ENV.sub(env, s)
    except Unres:
        return None
    return None if "$(" in s else s


def test(e: ast.expr) -> bool | None:
    """Whether an ``if`` test holds, read statically (module docstring); ``None``: not known."""
    if isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.Not):
        t = test(e.operand)
        return None if t is None else not t
    if isinstance(e, ast.BoolOp):
        got = [test(v) for v in e.values]
        if isinstance(e.op, ast.And):
            return False if False in got else (None if None in got else True)
        return True if True in got else (None if None in got else False)
    if isinstance(e, ast.Compare) and len(e.ops) == 1 and isinstance(e.ops[0], (ast.Eq, ast.NotEq)):
        a, b = _text(e.left), _text(e.comparators[0])
        if a is None or b is None:
            return None
        return (a == b) == isinstance(e.ops[0], ast.Eq)
    s = _text(e)
    return None if s is None else s != ""


def flat(body: list[ast.stmt], unknown: list[ast.If]) -> list[ast.stmt]:
    """``body``'s statements as they run: an ``if`` of known test is the
    statements of the branch it takes (in turn flattened); an ``if`` whose test
    is not known stays as written and is added to ``unknown``."""
    out: list[ast.stmt] = []
    for st in body:
        if isinstance(st, ast.If):
            t = test(st.test)
            if t is not None:
                out.extend(flat(st.body if t else st.orelse, unknown))
                continue
            unknown.append(st)
        out.append(st)
    return out


def grown(fn: ast.FunctionDef, name: str) -> ast.List | str:
    """The list variable ``name`` holds at the end of ``fn`` when it is bound
    once to a list in the statements ``fn`` runs (:func:`flat`) and then grown
    there in order by ``name.append(x)``, ``name.extend([...])`` or ``name +=
    [...]``; else why not (a binding inside a loop or an ``if`` not known:
    chosen at run time)."""
    def binds(x: ast.AST) -> bool:
        return isinstance(x, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in x.targets) \
            or isinstance(x, ast.AugAssign) and isinstance(x.target, ast.Name) and x.target.id == name \
            or isinstance(x, ast.Call) and isinstance(x.func, ast.Attribute) and x.func.attr in _GROW \
            and isinstance(x.func.value, ast.Name) and x.func.value.id == name
    top = [st.value if isinstance(st, ast.Expr) else st for st in flat(fn.body, [])]
    mine = {id(x) for x in top}
    nested = next((x for st in top for x in ast.walk(st) if binds(x) and id(x) not in mine), None)
    if nested is not None:
        return f"is grown at line {getattr(nested, 'lineno', fn.lineno)} inside a block or a loop (chosen at run time)"
    out: list[ast.expr] | None = None
    for x in top:
        if not binds(x):
            continue
        at = getattr(x, "lineno", fn.lineno)
        if isinstance(x, ast.Assign):
            v = expand(x.value)
            if out is not None or not isinstance(v, (ast.List, ast.Tuple)):
                return f"is bound at line {at} to what is not a list of actions"
            out = list(v.elts)
            continue
        more = x.value if isinstance(x, ast.AugAssign) else x.args[-1] if isinstance(x, ast.Call) and x.args else None
        if out is None or more is None:
            return f"is grown at line {at} before it is bound"
        if isinstance(x, ast.Call) and isinstance(x.func, ast.Attribute) and x.func.attr != "extend":
            out.append(more)  # append(x), insert(i, x): the order of actions does not change the graph
            continue
        more = expand(more)
        if not isinstance(more, (ast.List, ast.Tuple)):
            return f"is grown at line {at} by '{ast.unparse(more)}', not a list"
        out.extend(more.elts)
    return ast.List(elts=out or [], ctx=ast.Load())


def added(fn: ast.FunctionDef) -> list[tuple[ast.Call, ast.If | None]]:
    """The ``x.add_action(a)`` calls of ``fn`` in the statements it runs, each
    with the innermost ``if`` not known that holds it (``None``: it runs)."""
    unknown: list[ast.If] = []
    out: list[tuple[ast.Call, ast.If | None]] = []

    def walk(stmts: list[ast.stmt], under: ast.If | None) -> None:
        for st in flat(stmts, unknown):
            if isinstance(st, ast.If):  # its test is not known: both branches, said by the caller
                walk(st.body, st)
                walk(st.orelse, st)
                continue
            for x in ast.walk(st):
                if isinstance(x, ast.Call) and callee(x) == "add_action" and x.args:
                    out.append((x, under))

    walk(fn.body, None)
    return out
