"""Values of a ROS 2 Python launch file, read from its syntax tree (never
executed): the evaluator :mod:`launch_ros2` reads actions with.

* a name bound once (in the function read, else at module level) is its
  bound expression (:func:`expand`); a name bound more than once, by a loop,
  by ``+=`` or grown by ``.append`` / ``.extend`` / ``.insert`` is chosen at
  run time and named as such (:func:`unbound`);
* ``a + b`` of two lists or tuples is their concatenation;
* a list comprehension ``[f(x) for x in items if cond]`` over a list, a
  tuple, ``range(n)`` or ``d.items()`` of known items is the list of its
  elements with the loop variables (a name or a tuple of names) put in
  (:func:`unroll`); a condition must evaluate (:func:`.launch.evaluate`);
* a list of actions bound once and then grown in order is read by
  :mod:`launch_py_flow` (with the branches of ``if`` statements);
* a string value (:func:`value`): a literal, an f-string of known parts, a
  launch substitution as the ``$(...)`` text :class:`~.launch.Interpreter`
  resolves: ``LaunchConfiguration('x'[, default=d])`` (``$(var x)``),
  ``EnvironmentVariable('X'[, default_value=d])`` (``$(env X)`` /
  ``$(optenv X d)``), ``TextSubstitution(text=t)`` (``t``), Nav2's
  ``LaunchConfigAsBool('x')`` (``$(as-bool $(var x))``: ``True`` when the
  value stripped and lower-cased is ``true``, ``1``, ``yes`` or ``on``, else
  ``False``, as ``nav2_common.launch`` defines it),
  ``ThisLaunchFileDir()``, ``PythonExpression([...])`` (``$(eval ...)``),
  ``EqualsSubstitution`` / ``NotEqualsSubstitution``,
  ``get_package_share_directory`` / ``FindPackageShare``, ``os.path.join``,
  ``PathJoinSubstitution``; ``x.perform(context)`` is ``x``; other
  packages' substitution classes as :mod:`launch_subst` reads them.

What cannot be read raises :class:`Unres` naming what it is.

Source: launch's substitutions (``launch.substitutions``), launch_ros's
``FindPackageShare``; Python's list comprehension semantics (The Python
Language Reference, 6.2.4 "Displays for lists, sets and dictionaries").
"""
from __future__ import annotations

import ast
import copy

from rclverify.ros.extract.launch_subst import call_value as other_package
from rclverify.ros.extract.launch_tree import Unresolved, evaluate


class Unres(Exception):
    """A value that cannot be read statically (the message names what it is)."""


def callee(c: ast.Call) -> str:
    """The called name: ``Node`` for ``Node(...)`` and ``launch_ros.actions.Node(...)``."""
    f = c.func
    return f.attr if isinstance(f, ast.Attribute) else (f.id if isinstance(f, ast.Name) else "")


#: the variables the function read binds once (name -> expression), while one file is read
ENV: dict[str, ast.expr] = {}
#: the variables it binds more than once (chosen at run time): name -> lines
TWICE: dict[str, list[int]] = {}
HERE = [""]  # the launch file's name
MAX_DEPTH = 16  # names followed through names
MAX_UNROLL = 256  # elements one list comprehension gives

_GROW = ("append", "extend", "insert")


def kw(c: ast.Call, name: str) -> ast.expr | None:
    """The value of keyword argument ``name`` of call ``c`` (``None``: not given)."""
    return next((k.value for k in c.keywords if k.arg == name), None)


def arg(c: ast.Call, pos: int, name: str) -> ast.expr | None:
    """Argument ``name`` of ``c``, given at position ``pos`` or by keyword."""
    return c.args[pos] if len(c.args) > pos else kw(c, name)


def expand(e: ast.expr, depth: int = 0) -> ast.expr:
    """``e`` with each name bound once replaced by its bound expression, ``a + b``
    of two lists or tuples folded into one list and list comprehensions over
    known items unrolled; anything else is returned as written (the caller
    says what it cannot read)."""
    if depth > MAX_DEPTH:
        return e
    if isinstance(e, ast.Name) and e.id in ENV:
        return expand(ENV[e.id], depth + 1)
    if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
        a, b = expand(e.left, depth + 1), expand(e.right, depth + 1)
        if isinstance(a, (ast.List, ast.Tuple)) and isinstance(b, (ast.List, ast.Tuple)):
            return ast.copy_location(ast.List(elts=[*a.elts, *b.elts], ctx=ast.Load()), e)
        return e
    if isinstance(e, ast.ListComp):
        try:
            return expand(unroll(e, depth + 1), depth + 1)
        except Unres:
            return e
    if isinstance(e, (ast.List, ast.Tuple)):
        elts: list[ast.expr] = []
        for x in e.elts:
            x = expand(x, depth + 1)
            if isinstance(x, ast.Starred):
                inner = expand(x.value, depth + 1)
                if isinstance(inner, (ast.List, ast.Tuple)):
                    elts.extend(inner.elts)
                    continue
            elts.append(x)
        return ast.copy_location(ast.List(elts=elts, ctx=ast.Load()) if isinstance(e, ast.List)
                                 else ast.Tuple(elts=elts, ctx=ast.Load()), e)
    if isinstance(e, ast.Dict):
        return ast.copy_location(ast.Dict(keys=[k if k is None else expand(k, depth + 1) for k in e.keys],
                                          values=[expand(v, depth + 1) for v in e.values]), e)
    return e


class _Put(ast.NodeTransformer):
    """Loop variables replaced by their items (a copy each, located where the item is written)."""

    def __init__(self, binding: dict[str, ast.expr]) -> None:
        self.binding = binding

    def visit_Name(self, node: ast.Name) -> ast.AST:
        got = self.binding.get(node.id)
        return copy.deepcopy(got) if got is not None and isinstance(node.ctx, ast.Load) else node


def _items(it: ast.expr, depth: int) -> list[ast.expr]:
    it = expand(it, depth + 1)
    if isinstance(it, (ast.List, ast.Tuple)):
        return list(it.elts)
    if isinstance(it, ast.Call) and callee(it) == "range" and 1 <= len(it.args) <= 2 and not it.keywords:
        bounds = [expand(a, depth + 1) for a in it.args]
        if all(isinstance(b, ast.Constant) and type(b.value) is int for b in bounds):
            lo, hi = (0, bounds[0].value) if len(bounds) == 1 else (bounds[0].value, bounds[1].value)  # type: ignore[attr-defined]
            if hi - lo > MAX_UNROLL:
                raise Unres(f"'{ast.unparse(it)}' (more than {MAX_UNROLL} items)")
            return [ast.copy_location(ast.Constant(value=k), it) for k in range(lo, hi)]
    if isinstance(it, ast.Call) and isinstance(it.func, ast.Attribute) and it.func.attr == "items" and not it.args:
        d = expand(it.func.value, depth + 1)
        if isinstance(d, ast.Dict) and all(k is not None for k in d.keys):
            return [ast.copy_location(ast.Tuple(elts=[k, v], ctx=ast.Load()), v)  # type: ignore[list-item]
                    for k, v in zip(d.keys, d.values)]
    raise Unres(f"'{ast.unparse(it)}' (not a list of known items)")


def _bind(target: ast.expr, item: ast.expr, out: dict[str, ast.expr]) -> None:
    if isinstance(target, ast.Name):
        out[target.id] = item
        return
    if isinstance(target, (ast.Tuple, ast.List)) and isinstance(item, (ast.Tuple, ast.List)) \
            and len(target.elts) == len(item.elts):
        for t, x in zip(target.elts, item.elts):
            _bind(t, expand(x), out)
        return
    raise Unres(f"'{ast.unparse(target)}' over '{ast.unparse(item)}' (the items do not unpack)")


def unroll(comp: ast.ListComp, depth: int = 0) -> ast.List:
    """The list a comprehension of one ``for`` gives, its loop variables put in;
    raises :class:`Unres` when the items, the unpacking or a condition cannot
    be read."""
    if len(comp.generators) != 1 or comp.generators[0].is_async:
        raise Unres(f"'{ast.unparse(comp)}' (a comprehension of several loops)")
    gen = comp.generators[0]
    items = _items(gen.iter, depth)
    if len(items) > MAX_UNROLL:
        raise Unres(f"'{ast.unparse(gen.iter)}' (more than {MAX_UNROLL} items)")
    out: list[ast.expr] = []
    for item in items:
        binding: dict[str, ast.expr] = {}
        _bind(gen.target, expand(item, depth + 1), binding)
        keep = True
        for cond in gen.ifs:
            c = _Put(binding).visit(copy.deepcopy(cond))
            try:
                keep = keep and evaluate(_literal_text(c)) == "True"
            except Unresolved as exc:
                raise Unres(f"condition '{ast.unparse(cond)}' ({exc})") from None
        if keep:
            elt = _Put(binding).visit(copy.deepcopy(comp.elt))
            out.append(ast.fix_missing_locations(ast.copy_location(elt, comp.elt)))
    return ast.copy_location(ast.List(elts=out, ctx=ast.Load()), comp)


def _literal_text(e: ast.AST) -> str:
    """``e`` as Python text, names bound once put in (for :func:`.launch.evaluate`)."""
    class _Env(ast.NodeTransformer):
        def visit_Name(self, node: ast.Name) -> ast.AST:
            return expand(node) if node.id in ENV else node
    return ast.unparse(_Env().visit(copy.deepcopy(e)))


def unbound(e: ast.Name) -> Unres:
    """Why name ``e`` has no value read statically."""
    if e.id in TWICE:
        return Unres(f"variable '{e.id}' (assigned {len(TWICE[e.id])} times, lines "
                     f"{', '.join(map(str, TWICE[e.id]))}: chosen at run time)")
    return Unres(f"variable '{e.id}' (not assigned in generate_launch_description())")


_SOURCES = ("PythonLaunchDescriptionSource", "XMLLaunchDescriptionSource", "YAMLLaunchDescriptionSource",
            "AnyLaunchDescriptionSource", "FrontendLaunchDescriptionSource")


def value(e: ast.AST, depth: int = 0) -> str:
    """The string value of ``e`` (see the module docstring); raises :class:`Unres`."""
    if isinstance(e, ast.Constant) and isinstance(e.value, (str, int, float, bool)):
        return str(e.value).lower() if isinstance(e.value, bool) else str(e.value)
    if isinstance(e, ast.Name) and e.id in ENV and depth < MAX_DEPTH:
        return value(ENV[e.id], depth + 1)
    if isinstance(e, ast.Name):
        raise unbound(e)
    if isinstance(e, ast.Call):
        return _call_value(e, depth)
    if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
        x = expand(e)
        if x is not e:
            return value(x, depth + 1)
        return value(e.left, depth + 1) + value(e.right, depth + 1)  # str + str, a substitution + str
    if isinstance(e, (ast.List, ast.Tuple)) and all(isinstance(x, (ast.Constant, ast.Name, ast.Call, ast.BinOp,
                                                                   ast.JoinedStr)) for x in e.elts):
        return "".join(value(x, depth + 1) for x in e.elts)  # a list of substitutions concatenates
    if isinstance(e, ast.JoinedStr):
        parts = []
        for p in e.values:
            if isinstance(p, ast.FormattedValue) and (p.format_spec is not None or p.conversion not in (-1, 115)):
                raise Unres(f"an f-string with a format '{ast.unparse(e)}'")
            parts.append(value(p.value if isinstance(p, ast.FormattedValue) else p, depth + 1))
        return "".join(parts)
    raise Unres(f"'{ast.unparse(e)}' (not a literal or a known substitution)")


def _call_value(e: ast.Call, depth: int) -> str:
    name = callee(e)
    if name == "perform" and isinstance(e.func, ast.Attribute):  # LaunchConfiguration('x').perform(context)
        return value(e.func.value, depth + 1)
    if name == "LaunchConfiguration" and len(e.args) == 1:
        var = value(e.args[0], depth + 1)
        d = kw(e, "default")
        return f"$(var-default {var} {value(d, depth + 1)})" if d is not None else f"$(var {var})"
    if name == "EnvironmentVariable":
        n, d = arg(e, 0, "name"), kw(e, "default_value")
        if n is not None:
            return f"$(optenv {value(n, depth + 1)} {value(d, depth + 1)})" if d is not None \
                else f"$(env {value(n, depth + 1)})"
    if name == "LaunchConfigAsBool" and len(e.args) == 1:  # Nav2's nav2_common.launch substitution
        return f"$(as-bool $(var {value(e.args[0], depth + 1)}))"
    if name == "TextSubstitution":
        t = arg(e, 0, "text")
        if t is not None:
            return value(t, depth + 1)
    if name in ("ThisLaunchFileDir", "ThisLaunchFile") and not e.args:
        return "$(dirname)" if name == "ThisLaunchFileDir" else "$(dirname)/" + HERE[0]
    if name == "PythonExpression" and len(e.args) == 1:
        return f"$(eval {value(e.args[0], depth + 1)})"
    if name in ("EqualsSubstitution", "NotEqualsSubstitution") and len(e.args) == 2:
        a, b = (value(x, depth + 1) for x in e.args)
        if "'" in a + b or "\\" in a + b:
            raise Unres(f"'{ast.unparse(e)}' (a quote in a compared value)")
        return f"$(eval '{a}' {'==' if name == 'EqualsSubstitution' else '!='} '{b}')"
    got = other_package(e, name, lambda x: value(x, depth + 1), Unres)
    if got is not None:
        return got
    args = [value(a, depth + 1) for a in e.args]
    if name in ("get_package_share_directory", "FindPackageShare") and len(args) == 1:
        return f"$(find-pkg-share {args[0]})"
    if name == "join" and args:
        return "/".join(a.rstrip("/") for a in args)
    if name == "PathJoinSubstitution" and len(e.args) == 1:
        parts = expand(e.args[0])
        if isinstance(parts, (ast.List, ast.Tuple)):
            return "/".join(value(a, depth + 1).rstrip("/") for a in parts.elts)
    if name in _SOURCES and len(args) == 1:
        return args[0]
    raise Unres(f"'{ast.unparse(e)}' (not a literal or a known substitution)")


def once(stmts: list[ast.stmt] | list[ast.AST]) -> tuple[dict[str, ast.expr], dict[str, list[int]]]:
    """Names each simple assignment among ``stmts`` binds: those bound once
    (name -> expression) and those bound more often, by a loop, by ``+=`` or
    grown in place (``x.append(...)``) (name -> lines)."""
    seen: dict[str, ast.expr] = {}
    lines: dict[str, list[int]] = {}
    for st in stmts:
        if isinstance(st, ast.Expr):
            st = st.value  # a statement that is a call: x.append(...)
        if isinstance(st, (ast.Assign, ast.AnnAssign)):
            targets = st.targets if isinstance(st, ast.Assign) else [st.target]
            if len(targets) == 1 and isinstance(targets[0], ast.Name) and st.value is not None:
                lines.setdefault(targets[0].id, []).append(st.lineno)
                seen[targets[0].id] = st.value
        elif isinstance(st, (ast.AugAssign, ast.For)) and isinstance(st.target, ast.Name):
            lines.setdefault(st.target.id, []).append(st.lineno)  # x += [...], a loop's variable: not one value
        elif isinstance(st, ast.Call) and isinstance(st.func, ast.Attribute) and st.func.attr in _GROW \
                and isinstance(st.func.value, ast.Name):
            lines.setdefault(st.func.value.id, []).append(st.lineno)  # nodes.append(...): grown at run time
    twice = {k: sorted(set(v)) for k, v in lines.items() if len(set(v)) > 1}
    return {k: v for k, v in seen.items() if k not in twice}, twice
