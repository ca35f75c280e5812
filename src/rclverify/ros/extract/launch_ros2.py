"""ROS 2 Python launch files read statically with ``ast`` (never executed).

``generate_launch_description()``'s actions become the element tree of
:mod:`launch`: ``Node(package=, executable=, name=, namespace=,
remappings=[(a, b)])``, ``DeclareLaunchArgument('x', default_value='v')``,
``GroupAction([PushRosNamespace('ns'), ...])``, ``PushRosNamespace``,
``IncludeLaunchDescription(PythonLaunchDescriptionSource(path),
launch_arguments={...}.items())`` with ``path`` built from string literals,
``os.path.join``, ``get_package_share_directory('pkg')``,
``FindPackageShare('pkg')`` and ``PathJoinSubstitution([...])``;
``LaunchConfiguration('x')`` becomes ``$(var x)``; ``parameters=[{k: v}]``
of a node become ``param`` elements; ``ComposableNodeContainer`` /
``LoadComposableNodes`` with ``composable_node_descriptions=[ComposableNode(
package=, plugin=, name=, namespace=, remappings=, parameters=)]`` become
``node_container`` / ``load_composable_node`` with ``composable_node`` children.  Whatever else a value
is (a variable, a call), it is reported unresolved at its line.
"""
from __future__ import annotations

import ast
from pathlib import Path

from rclverify.ros.extract import safefs
from rclverify.ros.extract.launch import El
from rclverify.ros.extract.model import Note, Src


class _Unres(Exception):
    pass


def _callee(c: ast.Call) -> str:
    f = c.func
    return f.attr if isinstance(f, ast.Attribute) else (f.id if isinstance(f, ast.Name) else "")


#: the variables ``generate_launch_description()`` assigns, while one file is read
_ENV: dict[str, ast.expr] = {}
#: the variables it assigns more than once (chosen at run time): name -> lines
_TWICE: dict[str, list[int]] = {}
_HERE = [""]  # the launch file's name


def _value(e: ast.AST, depth: int = 0) -> str:
    if isinstance(e, ast.Constant) and isinstance(e.value, (str, int, float, bool)):
        return str(e.value).lower() if isinstance(e.value, bool) else str(e.value)
    if isinstance(e, ast.Name) and e.id in _ENV and depth < 8:
        return _value(_ENV[e.id], depth + 1)
    if isinstance(e, ast.Name) and e.id in _TWICE:
        raise _Unres(f"variable '{e.id}' (assigned {len(_TWICE[e.id])} times, lines "
                     f"{', '.join(map(str, _TWICE[e.id]))}: chosen at run time)")
    if isinstance(e, ast.Name):
        raise _Unres(f"variable '{e.id}' (not assigned in generate_launch_description())")
    if isinstance(e, ast.Call):
        name = _callee(e)
        if name == "LaunchConfiguration" and len(e.args) == 1:
            var = _value(e.args[0], depth + 1)
            d = _kw(e, "default")
            return f"$(var-default {var} {_value(d, depth + 1)})" if d is not None else f"$(var {var})"
        if name in ("ThisLaunchFileDir", "ThisLaunchFile") and not e.args:
            return "$(dirname)" if name == "ThisLaunchFileDir" else "$(dirname)/" + _HERE[0]
        args = [_value(a, depth + 1) for a in e.args]
        if name in ("get_package_share_directory", "FindPackageShare") and len(args) == 1:
            return f"$(find-pkg-share {args[0]})"
        if name == "join" and args:
            return "/".join(a.rstrip("/") for a in args)
        if name == "PathJoinSubstitution" and len(e.args) == 1 and isinstance(e.args[0], (ast.List, ast.Tuple)):
            return "/".join(_value(a).rstrip("/") for a in e.args[0].elts)
        if name in ("PythonLaunchDescriptionSource", "XMLLaunchDescriptionSource", "YAMLLaunchDescriptionSource",
                    "AnyLaunchDescriptionSource") and len(args) == 1:
            return args[0]
    if isinstance(e, (ast.List, ast.Tuple)) and all(isinstance(x, (ast.Constant, ast.Name, ast.Call)) for x in e.elts):
        return "".join(_value(x, depth + 1) for x in e.elts)  # a list of substitutions concatenates
    if isinstance(e, ast.JoinedStr):
        raise _Unres("an f-string")
    raise _Unres(f"'{ast.unparse(e)}' (not a literal or a known substitution)")


def _kw(c: ast.Call, name: str) -> ast.expr | None:
    return next((k.value for k in c.keywords if k.arg == name), None)


def _actions(e: ast.AST, shown: str, notes: list[Note]) -> list[El]:
    out: list[El] = []
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


def _action(c: ast.Call, shown: str, notes: list[Note]) -> El | None:
    src = Src(shown, c.lineno, c.col_offset + 1)
    name = _callee(c)
    try:
        if name == "Node":
            attrs: dict[str, str] = {}
            for py, key in (("package", "pkg"), ("executable", "exec"), ("name", "name"), ("namespace", "namespace"),
                            ("node_executable", "exec"), ("node_name", "name"), ("node_namespace", "namespace")):
                v = _kw(c, py)
                if v is not None:
                    attrs[key] = _value(v)
            return El("node", attrs, _node_kids(c, shown, notes), src)
        if name == "ComposableNode":
            attrs = {}
            for py, key in (("package", "pkg"), ("plugin", "plugin"), ("name", "name"), ("namespace", "namespace")):
                v = _kw(c, py)
                if v is not None:
                    attrs[key] = _value(v)
            return El("composable_node", attrs, _node_kids(c, shown, notes), src)
        if name in ("ComposableNodeContainer", "LoadComposableNodes"):
            descs = _kw(c, "composable_node_descriptions")
            kids = []
            if descs is not None:
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
            tag = "node_container" if name == "ComposableNodeContainer" else "load_composable_node"
            return El(tag, {}, kids, src)
        if name == "DeclareLaunchArgument":
            n = c.args[0] if c.args else _kw(c, "name")
            default = _kw(c, "default_value")
            attrs = {"name": _value(n)} if n is not None else {}
            if default is not None:
                attrs["default"] = _value(default)
            return El("arg", attrs, [], src)
        if name == "PushRosNamespace":
            n = c.args[0] if c.args else _kw(c, "namespace")
            return El("push-ros-namespace", {"namespace": _value(n)} if n is not None else {}, [], src)
        if name == "GroupAction":
            acts = c.args[0] if c.args else _kw(c, "actions")
            return El("group", {}, _actions(acts, shown, notes) if acts is not None else [], src)
        if name == "IncludeLaunchDescription":
            s = c.args[0] if c.args else _kw(c, "launch_description_source")
            kids = []
            la = _kw(c, "launch_arguments")
            if la is not None:
                if isinstance(la, ast.Call) and isinstance(la.func, ast.Attribute) and la.func.attr == "items":
                    la = la.func.value
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
            return El("include", {"file": _value(s)}, kids, src)
    except _Unres as exc:
        notes.append(Note(src, f"{name}(...): {exc} cannot be read statically; action skipped", "ROS-LAUNCH"))
    return None


def _node_kids(c: ast.Call, shown: str, notes: list[Note]) -> list[El]:
    """``remappings=[(a, b)]`` and ``parameters=[{name: value}]`` of a ``Node`` or
    ``ComposableNode`` as ``remap`` and ``param`` elements; a parameter file (a
    path in ``parameters``) is not read, said with a located note."""
    kids = []
    rm = _kw(c, "remappings")
    if rm is not None:
        if not isinstance(rm, (ast.List, ast.Tuple)):
            raise _Unres(f"remappings '{ast.unparse(rm)}'")
        for pair in rm.elts:
            if not isinstance(pair, (ast.Tuple, ast.List)) or len(pair.elts) != 2:
                raise _Unres(f"remapping '{ast.unparse(pair)}'")
            kids.append(El("remap", {"from": _value(pair.elts[0]), "to": _value(pair.elts[1])}, [],
                           Src(shown, pair.lineno, pair.col_offset + 1)))
    ps = _kw(c, "parameters")
    if isinstance(ps, (ast.List, ast.Tuple)):
        for item in ps.elts:
            at = Src(shown, item.lineno, item.col_offset + 1)
            if not isinstance(item, ast.Dict):
                notes.append(Note(at, f"parameters '{ast.unparse(item)}' are not a literal dict (a parameter "
                                      f"file is not read): not resolved statically", "ROS-LAUNCH"))
                continue
            for k, v in zip(item.keys, item.values):
                try:
                    if k is not None:
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
    """The actions of ``generate_launch_description()`` as an element tree."""
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
        return _read(fn, shown, notes)
    finally:
        _ENV.clear()
        _TWICE.clear()


def _read(fn: ast.FunctionDef | None, shown: str, notes: list[Note]) -> tuple[El | None, list[Note]]:
    if fn is None:
        return None, [Note(Src(shown), "no generate_launch_description() function", "ROS-PARSE", "error")]
    kids: list[El] = []
    assigned: dict[str, ast.expr] = {}
    counts: dict[str, list[int]] = {}
    for st in ast.walk(fn):
        if isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name):
            counts.setdefault(st.targets[0].id, []).append(st.lineno)
            _ENV[st.targets[0].id] = st.value
    for name, lines in counts.items():
        if len(lines) > 1:
            _ENV.pop(name)  # assigned twice: not one value
            _TWICE[name] = sorted(lines)
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
