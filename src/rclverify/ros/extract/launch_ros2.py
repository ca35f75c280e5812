"""ROS 2 Python launch files read statically with ``ast`` (never executed).

``generate_launch_description()``'s actions become the element tree of
:mod:`launch`: ``Node(package=, executable=, name=, namespace=,
remappings=[(a, b)])``, ``DeclareLaunchArgument('x', default_value='v')``,
``GroupAction([PushRosNamespace('ns'), ...])``, ``PushRosNamespace`` /
``PushROSNamespace``, ``IncludeLaunchDescription(PythonLaunchDescriptionSource(path),
launch_arguments={...}.items())`` with ``path`` built from string literals,
``os.path.join``, ``get_package_share_directory('pkg')``,
``FindPackageShare('pkg')`` and ``PathJoinSubstitution([...])``;
``LaunchConfiguration('x')`` becomes ``$(var x)``; ``parameters=[{k: v}]``
of a node become ``param`` elements; ``ComposableNodeContainer`` /
``LoadComposableNodes`` with ``composable_node_descriptions=[ComposableNode(
package=, plugin=, name=, namespace=, remappings=, parameters=)]`` become
``node_container`` / ``load_composable_node`` with ``composable_node`` children.

A small evaluator over the file's own syntax tree (:func:`_expand`) stands
for running it: a name bound once in ``generate_launch_description()`` (or,
failing that, once at module level) is its bound expression, ``a + b`` of two
lists or tuples is their concatenation, so ``remappings = [('/tf', 'tf')]``
then ``Node(..., remappings=remappings + [('cmd_vel', 'nav')])`` reads as the
three-pair list.  ``condition=IfCondition(x)`` / ``UnlessCondition(x)``
become ``if`` / ``unless`` attributes; ``PythonExpression([...])`` becomes
``$(eval ...)``, ``EqualsSubstitution(a, b)`` / ``NotEqualsSubstitution(a, b)``
an ``$(eval)`` comparison, all evaluated by :class:`~.launch.Interpreter`
once the launch arguments are known.

What cannot be read drops only what it is, with a located note: an
unreadable ``remappings``, ``parameters`` item, ``name`` or ``namespace``
leaves the node without it, an unreadable condition leaves the action
unconditional.  A node whose ``package`` or ``executable``/``plugin`` cannot
be read is skipped (nothing says which program it runs).
"""
from __future__ import annotations

import ast
from pathlib import Path

from rclverify.ros.extract import safefs
from rclverify.ros.extract.launch import UNREAD, El
from rclverify.ros.extract.model import Note, Src


class _Unres(Exception):
    pass


def _callee(c: ast.Call) -> str:
    f = c.func
    return f.attr if isinstance(f, ast.Attribute) else (f.id if isinstance(f, ast.Name) else "")


#: the variables ``generate_launch_description()`` (or the module) binds once, while one file is read
_ENV: dict[str, ast.expr] = {}
#: the variables it assigns more than once (chosen at run time): name -> lines
_TWICE: dict[str, list[int]] = {}
_HERE = [""]  # the launch file's name
MAX_DEPTH = 16  # names followed through names


def _expand(e: ast.expr, depth: int = 0) -> ast.expr:
    """``e`` with each name bound once replaced by its bound expression and
    ``a + b`` of two lists or tuples folded into one list; anything else is
    returned as written (the caller says what it cannot read)."""
    if depth > MAX_DEPTH:
        return e
    if isinstance(e, ast.Name) and e.id in _ENV:
        return _expand(_ENV[e.id], depth + 1)
    if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
        a, b = _expand(e.left, depth + 1), _expand(e.right, depth + 1)
        if isinstance(a, (ast.List, ast.Tuple)) and isinstance(b, (ast.List, ast.Tuple)):
            return ast.copy_location(ast.List(elts=[*a.elts, *b.elts], ctx=ast.Load()), e)
        return e
    if isinstance(e, (ast.List, ast.Tuple)):
        elts = [_expand(x, depth + 1) for x in e.elts]
        return ast.copy_location(ast.List(elts=elts, ctx=ast.Load()) if isinstance(e, ast.List)
                                 else ast.Tuple(elts=elts, ctx=ast.Load()), e)
    if isinstance(e, ast.Dict):
        return ast.copy_location(ast.Dict(keys=[k if k is None else _expand(k, depth + 1) for k in e.keys],
                                          values=[_expand(v, depth + 1) for v in e.values]), e)
    return e


def _unbound(e: ast.Name) -> _Unres:
    if e.id in _TWICE:
        return _Unres(f"variable '{e.id}' (assigned {len(_TWICE[e.id])} times, lines "
                      f"{', '.join(map(str, _TWICE[e.id]))}: chosen at run time)")
    return _Unres(f"variable '{e.id}' (not assigned in generate_launch_description())")


def _value(e: ast.AST, depth: int = 0) -> str:
    if isinstance(e, ast.Constant) and isinstance(e.value, (str, int, float, bool)):
        return str(e.value).lower() if isinstance(e.value, bool) else str(e.value)
    if isinstance(e, ast.Name) and e.id in _ENV and depth < MAX_DEPTH:
        return _value(_ENV[e.id], depth + 1)
    if isinstance(e, ast.Name):
        raise _unbound(e)
    if isinstance(e, ast.Call):
        name = _callee(e)
        if name == "LaunchConfiguration" and len(e.args) == 1:
            var = _value(e.args[0], depth + 1)
            d = _kw(e, "default")
            return f"$(var-default {var} {_value(d, depth + 1)})" if d is not None else f"$(var {var})"
        if name in ("ThisLaunchFileDir", "ThisLaunchFile") and not e.args:
            return "$(dirname)" if name == "ThisLaunchFileDir" else "$(dirname)/" + _HERE[0]
        if name == "PythonExpression" and len(e.args) == 1:
            return f"$(eval {_value(e.args[0], depth + 1)})"
        if name in ("EqualsSubstitution", "NotEqualsSubstitution") and len(e.args) == 2:
            a, b = (_value(x, depth + 1) for x in e.args)
            if "'" in a + b or "\\" in a + b:
                raise _Unres(f"'{ast.unparse(e)}' (a quote in a compared value)")
            return f"$(eval '{a}' {'==' if name == 'EqualsSubstitution' else '!='} '{b}')"
        args = [_value(a, depth + 1) for a in e.args]
        if name in ("get_package_share_directory", "FindPackageShare") and len(args) == 1:
            return f"$(find-pkg-share {args[0]})"
        if name == "join" and args:
            return "/".join(a.rstrip("/") for a in args)
        if name == "PathJoinSubstitution" and len(e.args) == 1:
            parts = _expand(e.args[0])
            if isinstance(parts, (ast.List, ast.Tuple)):
                return "/".join(_value(a, depth + 1).rstrip("/") for a in parts.elts)
        if name in ("PythonLaunchDescriptionSource", "XMLLaunchDescriptionSource", "YAMLLaunchDescriptionSource",
                    "AnyLaunchDescriptionSource", "FrontendLaunchDescriptionSource") and len(args) == 1:
            return args[0]
    if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
        x = _expand(e)
        if x is not e:
            return _value(x, depth + 1)
        return _value(e.left, depth + 1) + _value(e.right, depth + 1)  # str + str, a substitution + str
    if isinstance(e, (ast.List, ast.Tuple)) and all(isinstance(x, (ast.Constant, ast.Name, ast.Call, ast.BinOp))
                                                    for x in e.elts):
        return "".join(_value(x, depth + 1) for x in e.elts)  # a list of substitutions concatenates
    if isinstance(e, ast.JoinedStr):
        raise _Unres("an f-string")
    raise _Unres(f"'{ast.unparse(e)}' (not a literal or a known substitution)")


def _kw(c: ast.Call, name: str) -> ast.expr | None:
    return next((k.value for k in c.keywords if k.arg == name), None)


def _actions(e: ast.AST, shown: str, notes: list[Note]) -> list[El]:
    out: list[El] = []
    if isinstance(e, ast.expr):
        e = _expand(e)
    elems = e.elts if isinstance(e, (ast.List, ast.Tuple)) else [e]
    for x in elems:
        if isinstance(x, ast.Call):
            el = _action(x, shown, notes)
            if el is not None:
                out.append(el)
        elif isinstance(x, ast.Starred) or isinstance(x, ast.Name):
            notes.append(Note(Src(shown, x.lineno, x.col_offset + 1),
                              f"launch action '{ast.unparse(x)}' is not a literal call: not resolved statically",
                              "ROS-LAUNCH"))
    return out


def _required(c: ast.Call, attrs: dict[str, str], keys: tuple[tuple[str, str], ...]) -> None:
    """The keyword arguments ``keys`` (``(python name, attribute)``) of action
    ``c`` without which it starts nothing known (its package, executable or
    plugin): one that cannot be read raises :class:`_Unres` naming it."""
    for py, key in keys:
        v = _kw(c, py)
        if v is not None:
            try:
                attrs[key] = _value(v)
            except _Unres as exc:
                raise _Unres(f"{py} {exc}") from None


def _optional(c: ast.Call, attrs: dict[str, str], keys: tuple[tuple[str, str], ...], shown: str,
              notes: list[Note]) -> None:
    """The keyword arguments ``keys`` (``(python name, attribute)``) of action
    ``c`` that the node can do without: one that cannot be read is left out of
    ``attrs``, said with a located note."""
    what = _callee(c)
    for py, key in keys:
        v = _kw(c, py)
        if v is None:
            continue
        try:
            attrs[key] = _value(v)
        except _Unres as exc:
            notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"{what}(...): {py} {exc} cannot be read "
                              f"statically; the {py} the code gives is kept", "ROS-LAUNCH"))


def _condition(c: ast.Call, attrs: dict[str, str], shown: str, notes: list[Note]) -> None:
    """``condition=IfCondition(x)`` / ``UnlessCondition(x)`` of action ``c`` as
    an ``if`` / ``unless`` attribute; one that cannot be read leaves the action
    unconditional, said with a located note."""
    cond = _kw(c, "condition")
    if cond is None:
        return
    cond = _expand(cond)
    at = Src(shown, cond.lineno, cond.col_offset + 1)
    kind = _callee(cond) if isinstance(cond, ast.Call) else ""
    try:
        if kind not in ("IfCondition", "UnlessCondition") or not isinstance(cond, ast.Call) or len(cond.args) != 1:
            raise _Unres(f"'{ast.unparse(cond)}' (not IfCondition(x) or UnlessCondition(x))")
        attrs["if" if kind == "IfCondition" else "unless"] = _value(cond.args[0])
    except _Unres as exc:
        notes.append(Note(at, f"{_callee(c)}(...): condition {exc} cannot be read statically; the action is read "
                              f"as if it held", "ROS-LAUNCH"))
        attrs[UNREAD] = str(at)


def _action(c: ast.Call, shown: str, notes: list[Note]) -> El | None:
    src = Src(shown, c.lineno, c.col_offset + 1)
    name = _callee(c)
    try:
        attrs: dict[str, str] = {}
        if name == "Node":
            _required(c, attrs, (("package", "pkg"), ("executable", "exec"), ("node_executable", "exec")))
            _optional(c, attrs, (("name", "name"), ("namespace", "namespace"), ("node_name", "name"),
                                 ("node_namespace", "namespace")), shown, notes)
            _condition(c, attrs, shown, notes)
            return El("node", attrs, _node_kids(c, shown, notes), src)
        if name == "ComposableNode":
            _required(c, attrs, (("package", "pkg"), ("plugin", "plugin")))
            _optional(c, attrs, (("name", "name"), ("namespace", "namespace")), shown, notes)
            return El("composable_node", attrs, _node_kids(c, shown, notes), src)
        if name in ("ComposableNodeContainer", "LoadComposableNodes"):
            descs = _kw(c, "composable_node_descriptions")
            kids = []
            if descs is not None:
                descs = _expand(descs)
                if not isinstance(descs, (ast.List, ast.Tuple)):
                    raise _Unres(f"composable_node_descriptions '{ast.unparse(descs)}'")
                for d in descs.elts:
                    if isinstance(d, ast.Call) and _callee(d) == "ComposableNode":
                        el = _action(d, shown, notes)
                        if el is not None:
                            kids.append(el)
                    else:
                        notes.append(Note(Src(shown, d.lineno, d.col_offset + 1), f"composable node "
                                          f"'{ast.unparse(d)}' is not a literal ComposableNode(...): not resolved "
                                          f"statically", "ROS-LAUNCH"))
            _condition(c, attrs, shown, notes)
            tag = "node_container" if name == "ComposableNodeContainer" else "load_composable_node"
            return El(tag, attrs, kids, src)
        if name == "DeclareLaunchArgument":
            n = c.args[0] if c.args else _kw(c, "name")
            default = _kw(c, "default_value")
            if n is not None:
                attrs["name"] = _value(n)
            if default is not None:
                attrs["default"] = _value(default)
            _condition(c, attrs, shown, notes)
            return El("arg", attrs, [], src)
        if name in ("PushRosNamespace", "PushROSNamespace"):
            n = c.args[0] if c.args else _kw(c, "namespace")
            if n is not None:
                attrs["namespace"] = _value(n)
            _condition(c, attrs, shown, notes)
            return El("push-ros-namespace", attrs, [], src)
        if name == "GroupAction":
            acts = c.args[0] if c.args else _kw(c, "actions")
            _condition(c, attrs, shown, notes)
            return El("group", attrs, _actions(acts, shown, notes) if acts is not None else [], src)
        if name == "IncludeLaunchDescription":
            s = c.args[0] if c.args else _kw(c, "launch_description_source")
            kids = []
            la = _kw(c, "launch_arguments")
            if la is not None:
                if isinstance(la, ast.Call) and isinstance(la.func, ast.Attribute) and la.func.attr == "items":
                    la = la.func.value
                la = _expand(la)
                if isinstance(la, ast.Dict):
                    for k, v in zip(la.keys, la.values):
                        if k is not None:
                            kids.append(El("arg", {"name": _value(k), "value": _value(v)}, [], src))
                elif isinstance(la, (ast.List, ast.Tuple)):
                    for pair in la.elts:
                        if isinstance(pair, ast.Tuple) and len(pair.elts) == 2:
                            kids.append(El("arg", {"name": _value(pair.elts[0]), "value": _value(pair.elts[1])}, [], src))
                else:
                    raise _Unres(f"launch_arguments '{ast.unparse(la)}'")
            if s is None:
                raise _Unres("an include without a source")
            attrs["file"] = _value(s)
            _condition(c, attrs, shown, notes)
            return El("include", attrs, kids, src)
    except _Unres as exc:
        notes.append(Note(src, f"{name}(...): {exc} cannot be read statically; action skipped", "ROS-LAUNCH"))
    return None


def _node_kids(c: ast.Call, shown: str, notes: list[Note]) -> list[El]:
    """``remappings=[(a, b)]`` and ``parameters=[{name: value}]`` of a ``Node`` or
    ``ComposableNode`` as ``remap`` and ``param`` elements, through names bound
    once and list concatenation (:func:`_expand`); a parameter file (a path in
    ``parameters``), an unreadable pair or value is left out with a located
    note.  A parameter whose value is a list of literals (a string array) is
    no name and is not kept."""
    kids = []
    rm = _kw(c, "remappings")
    if rm is not None:
        rm = _expand(rm)
        if not isinstance(rm, (ast.List, ast.Tuple)):
            notes.append(Note(Src(shown, rm.lineno, rm.col_offset + 1), f"{_callee(c)}(...): remappings "
                              f"'{ast.unparse(rm)}' cannot be read statically; the node is read without them",
                              "ROS-LAUNCH"))
        else:
            for pair in rm.elts:
                at = Src(shown, pair.lineno, pair.col_offset + 1)
                try:
                    if not isinstance(pair, (ast.Tuple, ast.List)) or len(pair.elts) != 2:
                        raise _Unres(f"'{ast.unparse(pair)}' (not a pair)")
                    kids.append(El("remap", {"from": _value(pair.elts[0]), "to": _value(pair.elts[1])}, [], at))
                except _Unres as exc:
                    notes.append(Note(at, f"{_callee(c)}(...): remapping {exc} cannot be read statically; "
                                          f"remapping left out", "ROS-LAUNCH"))
    ps = _kw(c, "parameters")
    ps = _expand(ps) if ps is not None else None
    if isinstance(ps, (ast.List, ast.Tuple)):
        for item in ps.elts:
            at = Src(shown, item.lineno, item.col_offset + 1)
            if not isinstance(item, ast.Dict):
                notes.append(Note(at, f"parameters '{ast.unparse(item)}' are not a literal dict (a parameter "
                                      f"file is not read): not resolved statically", "ROS-LAUNCH"))
                continue
            for k, v in zip(item.keys, item.values):
                if k is None:
                    continue
                if isinstance(v, (ast.List, ast.Tuple)) and v.elts and all(isinstance(x, ast.Constant)
                                                                             for x in v.elts):
                    continue  # a string (or number) array: a list value, never a name
                try:
                    kids.append(El("param", {"name": _value(k), "value": _value(v)}, [],
                                   Src(shown, v.lineno, v.col_offset + 1)))
                except _Unres as exc:
                    notes.append(Note(at, f"parameter value {exc} is not a literal: not resolved statically",
                                      "ROS-LAUNCH"))
    elif ps is not None:
        notes.append(Note(Src(shown, ps.lineno, ps.col_offset + 1), f"parameters '{ast.unparse(ps)}' are not a "
                                                                    f"literal list: not resolved statically",
                          "ROS-LAUNCH"))
    return kids


def read_python(path: Path, shown: str) -> tuple[El | None, list[Note]]:
    """The actions of ``generate_launch_description()`` of the Python launch
    file ``path`` (shown as ``shown`` in locations) as an element tree (root
    ``launch``) and the notes of what could not be read; a file that does not
    parse or has no such function gives ``None`` and an error note."""
    try:
        tree = ast.parse(safefs.read_text(path), filename=shown)
    except (SyntaxError, ValueError) as exc:
        return None, [Note(Src(shown, getattr(exc, "lineno", None) or 1, getattr(exc, "offset", None) or 1),
                           f"Python launch file does not parse: {getattr(exc, 'msg', exc)}", "ROS-PARSE", "error")]
    except (OSError, RecursionError, MemoryError) as exc:
        return None, [Note(Src(shown), f"cannot read: {exc}", "ROS-PARSE", "error")]
    notes: list[Note] = []
    fn = next((f for f in tree.body if isinstance(f, ast.FunctionDef) and f.name == "generate_launch_description"), None)
    _ENV.clear()
    _TWICE.clear()
    _HERE[0] = path.name
    try:
        _bind(tree, fn)
        return _read(fn, shown, notes)
    finally:
        _ENV.clear()
        _TWICE.clear()


def _once(stmts: list[ast.stmt] | list[ast.AST]) -> tuple[dict[str, ast.expr], dict[str, list[int]]]:
    """Names each simple assignment among ``stmts`` binds: those bound once
    (name -> expression) and those bound more often (name -> lines)."""
    seen: dict[str, ast.expr] = {}
    lines: dict[str, list[int]] = {}
    for st in stmts:
        if isinstance(st, (ast.Assign, ast.AnnAssign)):
            targets = st.targets if isinstance(st, ast.Assign) else [st.target]
            if len(targets) == 1 and isinstance(targets[0], ast.Name) and st.value is not None:
                lines.setdefault(targets[0].id, []).append(st.lineno)
                seen[targets[0].id] = st.value
        elif isinstance(st, (ast.AugAssign, ast.For)) and isinstance(st.target, ast.Name):
            lines.setdefault(st.target.id, []).append(st.lineno)  # x += [...], a loop's variable: not one value
    twice = {k: sorted(v) for k, v in lines.items() if len(v) > 1}
    return {k: v for k, v in seen.items() if k not in twice}, twice


def _bind(tree: ast.Module, fn: ast.FunctionDef | None) -> None:
    """Fill :data:`_ENV` and :data:`_TWICE`: the function's names, then the
    module's names it does not bind itself."""
    mod_once, mod_twice = _once(list(tree.body))
    fn_once, fn_twice = _once(list(ast.walk(fn))) if fn is not None else ({}, {})
    mine = set(fn_once) | set(fn_twice)
    _ENV.update({k: v for k, v in mod_once.items() if k not in mine})
    _TWICE.update({k: v for k, v in mod_twice.items() if k not in mine})
    _ENV.update(fn_once)
    _TWICE.update(fn_twice)


def _read(fn: ast.FunctionDef | None, shown: str, notes: list[Note]) -> tuple[El | None, list[Note]]:
    if fn is None:
        return None, [Note(Src(shown), "no generate_launch_description() function", "ROS-PARSE", "error")]
    kids: list[El] = []
    assigned: dict[str, ast.expr] = {}
    for st in ast.walk(fn):
        if isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name):
            assigned[st.targets[0].id] = st.value
        if isinstance(st, ast.Return) and st.value is not None:
            v = st.value
            if isinstance(v, ast.Call) and _callee(v) == "LaunchDescription":
                arg = v.args[0] if v.args else None
                if isinstance(arg, ast.Name) and arg.id in assigned:
                    arg = assigned[arg.id]
                if arg is not None:
                    elems = arg.elts if isinstance(arg, (ast.List, ast.Tuple)) else [arg]
                    resolved = [assigned.get(x.id, x) if isinstance(x, ast.Name) else x for x in elems]
                    kids.extend(_actions(ast.List(elts=resolved, ctx=ast.Load()), shown, notes))
                # ld.add_action(x) calls
            for call in ast.walk(fn):
                if isinstance(call, ast.Call) and _callee(call) == "add_action" and call.args:
                    a = call.args[0]
                    a = assigned.get(a.id, a) if isinstance(a, ast.Name) else a
                    kids.extend(_actions(a, shown, notes))
            break
    return El("launch", {}, kids, Src(shown, fn.lineno)), notes
