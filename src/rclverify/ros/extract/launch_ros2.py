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
from rclverify.ros.extract.launch_tree import UNREAD, El
from rclverify.ros.extract.launch_py_values import ENV as _ENV, HERE as _HERE, TWICE as _TWICE
from rclverify.ros.extract.launch_py_values import Unres as _Unres, arg as _arg, callee as _callee
from rclverify.ros.extract.launch_py_values import expand as _expand, kw as _kw, once as _once, unroll as _unroll
from rclverify.ros.extract.launch_py_values import value as _value
from rclverify.ros.extract.launch_py_flow import added as _added, grown as _grown
from rclverify.ros.extract.launch_py_actions import CONFIG_STACK, HANDLERS, PAIRS, QUIET, group_flags as _group_flags
from rclverify.ros.extract.launch_py_actions import group_keep as _group_keep
from rclverify.ros.extract.launch_py_actions import at_shutdown as _shutdown, condition as _cond
from rclverify.ros.extract.launch_py_actions import optional as _opt, required as _req
from rclverify.ros.extract.launch_py_functions import FN as _FN, FUNCS as _FUNCS, called as _called
from rclverify.ros.extract.launch_py_node import execute_process, node_kids as _node_kids, ros_args as _ros_args
from rclverify.ros.extract.model import Note, Src



def _actions(e: ast.AST, shown: str, notes: list[Note]) -> list[El]:
    """The actions of list (or single action) ``e``: each call read by
    :func:`_action`; what is no call of a known action is named in a located
    note (every miss said)."""
    out: list[El] = []
    if isinstance(e, ast.expr):
        e = _expand(e)
    elems = e.elts if isinstance(e, (ast.List, ast.Tuple)) else [e]
    if len(elems) == 1 and isinstance(elems[0], ast.Name) and elems[0].id in _TWICE and _FN:
        got = _grown(_FN[-1], elems[0].id)  # a list of actions grown before it is used
        if isinstance(got, str):
            v = elems[0]
            notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"launch actions '{v.id}' {got}: not "
                              f"resolved statically", "ROS-LAUNCH"))
            return out
        elems = got.elts
    for x in elems:
        if isinstance(x, ast.Starred) and isinstance(x.value, ast.ListComp):
            x = x.value  # *[... for ...] that did not unroll: said as a comprehension
        if isinstance(x, ast.Call):
            el = _action(x, shown, notes)
            if el is not None:
                out.append(el)
        elif isinstance(x, ast.ListComp):
            try:
                _unroll(x)  # the reason it did not unroll
            except _Unres as exc:
                notes.append(Note(Src(shown, x.lineno, x.col_offset + 1), f"launch actions built by a list "
                                  f"comprehension over {exc} cannot be read statically; the nodes it starts are "
                                  f"unknown", "ROS-LAUNCH"))
        elif isinstance(x, (ast.Starred, ast.Name, ast.Subscript, ast.IfExp, ast.BinOp)):
            notes.append(Note(Src(shown, x.lineno, x.col_offset + 1),
                              f"launch action '{ast.unparse(x)}' is not a literal call: not resolved statically",
                              "ROS-LAUNCH"))
    return out


def _action(c: ast.Call, shown: str, notes: list[Note]) -> El | None:
    src = Src(shown, c.lineno, c.col_offset + 1)
    name = _callee(c)
    try:
        attrs: dict[str, str] = {}
        if name in ("Node", "LifecycleNode"):
            _req(c, attrs, (("package", "pkg"), ("executable", "exec"), ("node_executable", "exec")))
            _opt(c, attrs, (("name", "name"), ("namespace", "namespace"), ("node_name", "name"),
                                 ("node_namespace", "namespace")), shown, notes)
            _ros_args(c, attrs, shown, notes)
            _cond(c, attrs, shown, notes)
            return El("node", attrs, _node_kids(c, shown, notes), src)
        if name == "ComposableNode":
            _req(c, attrs, (("package", "pkg"), ("plugin", "plugin")))
            _opt(c, attrs, (("name", "name"), ("namespace", "namespace")), shown, notes)
            return El("composable_node", attrs, _node_kids(c, shown, notes), src)
        if name in ("ComposableNodeContainer", "LoadComposableNodes"):
            return _container(c, name, attrs, src, shown, notes)
        if name == "DeclareLaunchArgument":
            n = c.args[0] if c.args else _kw(c, "name")
            default = _kw(c, "default_value")
            if n is not None:
                attrs["name"] = _value(n)
            if default is not None:
                try:
                    attrs["default"] = _value(default)
                except _Unres as exc:
                    notes.append(Note(Src(shown, default.lineno, default.col_offset + 1), f"{name}(...): "
                                      f"default_value {exc} cannot be read statically; the argument has no value "
                                      f"unless one is given", "ROS-LAUNCH"))
            _cond(c, attrs, shown, notes)
            return El("arg", attrs, [], src)
        if name in ("PushRosNamespace", "PushROSNamespace"):
            n = c.args[0] if c.args else _kw(c, "namespace")
            if n is not None:
                attrs["namespace"] = _value(n)
            _cond(c, attrs, shown, notes)
            return El("push-ros-namespace", attrs, [], src)
        if name == "GroupAction":
            acts = c.args[0] if c.args else _kw(c, "actions")
            _cond(c, attrs, shown, notes)
            return El("group", _group_flags(c, attrs, shown, notes), _group_keep(c, shown, notes)
                      + (_actions(acts, shown, notes) if acts is not None else []), src)
        if name == "IncludeLaunchDescription":
            return _include(c, attrs, src, shown, notes)
        return _more(c, name, attrs, src, shown, notes)
    except _Unres as exc:
        notes.append(Note(src, f"{name}(...): {exc} cannot be read statically; action skipped", "ROS-LAUNCH"))
    return None


def _container(c: ast.Call, name: str, attrs: dict[str, str], src: Src, shown: str, notes: list[Note]) -> El:
    """``ComposableNodeContainer`` / ``LoadComposableNodes`` with its
    ``composable_node_descriptions``; raises :class:`_Unres`."""
    if name == "ComposableNodeContainer":
        _opt(c, attrs, (("name", "name"), ("namespace", "namespace")), shown, notes)
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
    _cond(c, attrs, shown, notes)
    tag = "node_container" if name == "ComposableNodeContainer" else "load_composable_node"
    return El(tag, attrs, kids, src)


def _include(c: ast.Call, attrs: dict[str, str], src: Src, shown: str, notes: list[Note]) -> El:
    """``IncludeLaunchDescription(source, launch_arguments=...)``; raises :class:`_Unres`."""
    s = c.args[0] if c.args else _kw(c, "launch_description_source")
    kids = []
    la = _kw(c, "launch_arguments")
    if la is not None:
        if isinstance(la, ast.Call) and isinstance(la.func, ast.Attribute) and la.func.attr == "items":
            la = la.func.value
        la = _expand(la)
        if isinstance(la, ast.Dict):
            pairs = [(k, v) for k, v in zip(la.keys, la.values) if k is not None]
        elif isinstance(la, (ast.List, ast.Tuple)):
            pairs = [(p.elts[0], p.elts[1]) for p in la.elts if isinstance(p, ast.Tuple) and len(p.elts) == 2]
        else:
            raise _Unres(f"launch_arguments '{ast.unparse(la)}'")
        for k, v in pairs:
            n = _value(k)
            try:
                kids.append(El("arg", {"name": n, "value": _value(v)}, [], src))
            except _Unres as exc:  # the included file gets the argument without a value, never its default
                notes.append(Note(Src(shown, v.lineno, v.col_offset + 1), f"IncludeLaunchDescription(...): "
                                  f"argument '{n}' {exc} cannot be read statically; the included file reads it "
                                  f"without a value", "ROS-LAUNCH"))
                kids.append(El("arg", {"name": n, "novalue": "1"}, [], src))
    if s is None:
        raise _Unres("an include without a source")
    attrs["file"] = _value(s)
    _cond(c, attrs, shown, notes)
    return El("include", attrs, kids, src)


def _more(c: ast.Call, name: str, attrs: dict[str, str], src: Src, shown: str, notes: list[Note]) -> El | None:
    """The actions other than nodes, arguments, groups and includes: remaps and
    configurations set in a scope, timers and event handlers (their actions
    started), ``OpaqueFunction`` and the launch file's own functions
    (evaluated, :func:`_function_actions`); any other call is named in a
    located note."""
    if name in PAIRS:  # two positional-or-keyword arguments set in the scope
        tag, (k1, a1), (k2, a2), missing = PAIRS[name]
        x, y = _arg(c, 0, k1), _arg(c, 1, k2)
        if x is None or y is None:
            raise _Unres(missing)
        attrs.update({a1: _value(x), a2: _value(y)})
        _cond(c, attrs, shown, notes)
        return El(tag, attrs, [], src)
    acts: ast.expr | None = None
    if name in ("TimerAction", "RosTimer", "ROSTimer"):
        acts = _arg(c, 1, "actions")
    elif name == "RegisterEventHandler":
        h = _arg(c, 0, "event_handler")
        h = _expand(h) if h is not None else None
        kind = _callee(h) if isinstance(h, ast.Call) else ""
        acts = next((a for k in HANDLERS.get(kind, ()) if isinstance(h, ast.Call)
                     and (a := _kw(h, k)) is not None), None)  # the handlers' arguments are keyword-only
        if acts is None:
            raise _Unres(f"event handler '{ast.unparse(h) if h is not None else ''}' (not one of "
                         f"{', '.join(sorted(HANDLERS))} with its actions)")
        if isinstance(_expand(acts), ast.Lambda) or kind == "OnProcessIO":
            raise _Unres(f"the actions of {kind}, a function run at the event,")
        if kind == "OnShutdown":  # nothing it starts runs: its nodes are said, what else it cannot read is moot
            _shutdown(_actions(acts, shown, []), src, notes)
            return None
    elif name == "OpaqueFunction" or name in _FUNCS:
        fn = _arg(c, 0, "function") if name == "OpaqueFunction" else c.func
        got = _function_actions(fn, c, name == "OpaqueFunction", shown, notes)
        if isinstance(got, str):
            what = f"OpaqueFunction {ast.unparse(fn) if fn is not None else '?'}" if name == "OpaqueFunction" \
                else f"function {name}()"
            notes.append(Note(src, f"{what} not evaluated: {got}; the nodes it starts are unknown", "ROS-LAUNCH"))
            return None
        _cond(c, attrs, shown, notes)
        return El("group", {**attrs, "scoped": "false"}, got, src)
    elif name in CONFIG_STACK:  # ResetLaunchConfigurations: an unscoped group marked reset, with its keeps
        _cond(c, attrs, shown, notes)
        if name != "ResetLaunchConfigurations":
            return El(CONFIG_STACK[name], attrs, [], src)
        return El("group", {**attrs, "scoped": "false", "reset": "true"}, _group_keep(c, shown, notes), src)
    elif name == "ExecuteProcess":
        el = execute_process(c, src, notes)
        if el is not None:
            _cond(c, el.attrs, shown, notes)
        return el
    elif name in QUIET:
        return None
    else:
        notes.append(Note(src, f"launch action {name or ast.unparse(c.func)}(...) is not one the scan reads: the "
                               f"nodes it starts, if any, are unknown", "ROS-LAUNCH"))
        return None
    _cond(c, attrs, shown, notes)
    return El("group", {**attrs, "scoped": "false"}, _actions(acts, shown, notes) if acts is not None else [], src)


def _function_actions(fn: ast.expr | None, call: ast.Call, opaque: bool, shown: str,
                      notes: list[Note]) -> list[El] | str:
    """The actions a function of the launch file returns (:func:`~.launch_py_functions.called`), or why
    they are not read (a string)."""
    with _called(fn, call, opaque) as ret:
        return ret if isinstance(ret, str) else _actions(ret, shown, notes)


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
    _FUNCS.clear()
    _FUNCS.update({f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)
                   and f.name != "generate_launch_description"})
    _HERE[0] = path.name
    _FN[:] = [fn] if fn is not None else []
    try:
        _bind(tree, fn)
        return _read(fn, shown, notes)
    finally:
        _FN.clear()
        _ENV.clear()
        _TWICE.clear()
        _FUNCS.clear()


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
                if isinstance(arg, ast.Name) and arg.id in _TWICE:  # a list grown before it is returned
                    grown = _grown(fn, arg.id)
                    if isinstance(grown, str):
                        notes.append(Note(Src(shown, arg.lineno, arg.col_offset + 1), f"launch actions "
                                          f"'{arg.id}' {grown}: not resolved statically", "ROS-LAUNCH"))
                    arg = grown if not isinstance(grown, str) else assigned.get(arg.id, arg)
                elif isinstance(arg, ast.Name) and arg.id in assigned:
                    arg = assigned[arg.id]
                if arg is not None:
                    elems = arg.elts if isinstance(arg, (ast.List, ast.Tuple)) else [arg]
                    resolved = [assigned.get(x.id, x) if isinstance(x, ast.Name) else x for x in elems]
                    kids.extend(_actions(ast.List(elts=resolved, ctx=ast.Load()), shown, notes))
            for call, under in _added(fn):  # ld.add_action(x) calls, in the statements that run
                a = call.args[0]
                a = assigned.get(a.id, a) if isinstance(a, ast.Name) else a
                got = _actions(a, shown, notes)
                if under is not None and got:
                    at = Src(shown, under.lineno, under.col_offset + 1)
                    notes.append(Note(Src(shown, call.lineno, call.col_offset + 1), f"add_action(...) under "
                                      f"'if {ast.unparse(under.test)}' ({at}), a test not read statically: "
                                      f"the actions are read as if it held", "ROS-LAUNCH"))
                    got = [El("group", {UNREAD: str(at), "scoped": "false"}, got, at)]
                kids.extend(got)
            break
    return El("launch", {}, kids, Src(shown, fn.lineno)), notes
