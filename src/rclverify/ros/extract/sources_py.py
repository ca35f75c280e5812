"""Publishers, subscribers, services, actions and node names in Python node
sources, read with Python's ``ast`` (the code is never imported or run); a
file ``ast`` cannot parse (a Python 2 script, a broken file) is read by the
tolerant reader :mod:`sources_py_tolerant` (tree-sitter-python) instead.

Both readers give the same record of the file (:class:`PyModule`: imports,
calls, assignments), read here.  Recognised (rospy and actionlib, ROS 1;
rclpy, ROS 2):

* ``rospy.Publisher(name, data_class)``, ``rospy.Subscriber(name, data_class, cb)``,
  ``rospy.Service(name, service_class, handler)``, ``rospy.ServiceProxy(name, service_class)``
  (also imported bare; keyword arguments too);
* ``actionlib.SimpleActionServer(name, XAction, ...)`` / ``ActionServer``,
  ``actionlib.SimpleActionClient(name, XAction)`` / ``ActionClient``
  (``pkg.msg.XAction`` is the action ``pkg/action/X``);
* ``<x>.create_publisher(T, topic)``, ``<x>.create_subscription(T, topic, cb)``,
  ``<x>.create_service(T, name, cb)``, ``<x>.create_client(T, name)``,
  ``rclpy.action.ActionServer(node, T, name, cb)`` / ``ActionClient(node, T, name)``;
* library helpers (:mod:`py_helpers`: tf, message_filters,
  ``wait_for_message``, interactive markers, parameter events);
* names (:mod:`pyconst`): literals, constants, concatenations, parameters
  (``rospy.get_param('~topic', 'default')``; rclpy ``declare_parameter`` /
  ``get_parameter``: the node's ``~topic``), and what only the program knows
  (a function's parameter, ``self.topic``, an imported constant), left to
  the linker (:mod:`link`);
* types through imports, ``from pkg.msg import *`` (candidates the linker
  chooses among by the type table) and ``numpy_msg(T)``; a name imported
  twice (chosen at run time) is read as its first import, said in a note;
* node names from ``rospy.init_node(n)``, ``rclpy.create_node(n)``,
  ``Node(n)`` and ``super().__init__(n)`` (``n`` a literal, or any name in a
  class deriving from ``Node``);
* for the linker: functions and their parameters, classes, the calls of the
  package's own classes and functions with their argument values, attribute
  bindings, module constants, imports.

A name that is not read statically is reported unresolved at its location,
never guessed.
"""
from __future__ import annotations

import ast
from typing import Any

from rclverify.ros.extract import emit, names, py_helpers, symbols
from rclverify.ros.extract.cpp_types import action_type, service_type
from rclverify.ros.extract.model import Endpoint, Note, Src, canon_type
from rclverify.ros.extract.pyconst import DISCOVERY, PyScope
from rclverify.ros.extract.pyrecords import PyCall, PyModule, PyVal, percent


# (role, index and keyword of the name, index and keyword of the type), by callee
_CTORS = {
    "rospy.Publisher": ("pub", 0, "name", 1, "data_class"),
    "rospy.Subscriber": ("sub", 0, "name", 1, "data_class"),
    "rospy.Service": ("service_servers", 0, "name", 1, "service_class"),
    "rospy.ServiceProxy": ("service_clients", 0, "name", 1, "service_class"),
    "SimpleActionServer": ("action_servers", 0, "name", 1, "ActionSpec"),
    "SimpleActionClient": ("action_clients", 0, "ns", 1, "ActionSpec"),
    "ActionServer": ("action_servers", 0, "ns", 1, "ActionSpec"),
    "ActionClient": ("action_clients", 0, "ns", 1, "ActionSpec"),
    "rclpy.ActionServer": ("action_servers", 2, "action_name", 1, "action_type"),
    "rclpy.ActionClient": ("action_clients", 2, "action_name", 1, "action_type"),
}
_METHODS = {"create_publisher": ("pub", 1, "topic", 0, "msg_type"),
            "create_lifecycle_publisher": ("pub", 1, "topic", 0, "msg_type"),
            "create_subscription": ("sub", 1, "topic", 0, "msg_type"),
            "create_service": ("service_servers", 1, "srv_name", 0, "srv_type"),
            "create_client": ("service_clients", 1, "srv_name", 0, "srv_type")}
_WHAT = emit.WHAT
_short = emit.short


def _dotted(e: ast.AST) -> str | None:
    if isinstance(e, ast.Name):
        return e.id
    if isinstance(e, ast.Attribute):
        base = _dotted(e.value)
        return f"{base}.{e.attr}" if base else None
    return None


def _ast_module(tree: ast.AST, shown: str) -> PyModule:
    mod = PyModule()
    made: dict[int, PyCall] = {}

    def loc(e: ast.AST) -> Src:
        return Src(shown, getattr(e, "lineno", 1), getattr(e, "col_offset", 0) + 1)

    def call(c: ast.Call) -> PyCall:
        if id(c) not in made:
            f = c.func
            func = _dotted(f) or ""
            if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Call) and _dotted(f.value.func) == "super":
                func = f"super().{f.attr}"
            elif not func and isinstance(f, ast.Attribute):
                func = f".{f.attr}"
            made[id(c)] = PyCall(func, [val(a) for a in c.args],
                                 {k.arg: val(k.value) for k in c.keywords if k.arg}, loc(c))
        return made[id(c)]

    def val(e: ast.AST) -> PyVal:
        if isinstance(e, ast.Constant) and isinstance(e.value, str):
            return PyVal("str", e.value, loc(e))
        d = _dotted(e)
        if d is not None:
            return PyVal("name", d, loc(e))
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Add):
            return PyVal("cat", ast.unparse(e), loc(e), parts=[val(e.left), val(e.right)])
        if isinstance(e, ast.BinOp) and isinstance(e.op, ast.Mod) and isinstance(e.left, ast.Constant) \
                and isinstance(e.left.value, str):  # '/%s/pose' % name
            args = e.right.elts if isinstance(e.right, ast.Tuple) else [e.right]
            return percent(e.left.value, [val(a) for a in args], ast.unparse(e), loc(e))
        if isinstance(e, ast.JoinedStr):
            parts = [val(x.value) if isinstance(x, ast.FormattedValue) and x.conversion == -1 and x.format_spec is None
                     else val(x) if isinstance(x, ast.Constant) else PyVal("other", ast.unparse(x), loc(e))
                     for x in e.values]
            return PyVal("cat", ast.unparse(e), loc(e), parts=parts)
        chain, x = [], e  # a call and the attributes/calls on its result: get_parameter('t').value
        while isinstance(x, (ast.Call, ast.Attribute)):
            if isinstance(x, ast.Call):
                chain.append(call(x))
                x = x.func
            else:
                x = x.value
        if isinstance(e, ast.Call):
            return PyVal("call", ast.unparse(e), loc(e), call(e), chain)
        return PyVal("other", ast.unparse(e), loc(e), None, chain if isinstance(e, ast.Attribute) else [])

    def scopes(body: list[ast.stmt], prefix: str, in_class: bool) -> None:
        for st in body:
            if isinstance(st, ast.ClassDef):
                scopes(st.body, f"{prefix}{st.name}.", True)
            elif isinstance(st, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = st.args
                pos = a.posonlyargs + a.args
                static = any(_dotted(d) == "staticmethod" for d in st.decorator_list)
                names = [x.arg for x in pos] + [x.arg for x in a.kwonlyargs]
                defaults: list[PyVal | None] = [None] * (len(pos) - len(a.defaults)) + [val(d) for d in a.defaults]
                defaults += [val(d) if d is not None else None for d in a.kw_defaults]
                if in_class and not static and names:
                    names, defaults = names[1:], defaults[1:]
                mod.functions.append((f"{prefix}{st.name}", st.lineno, getattr(st, "end_lineno", None) or st.lineno,
                                      names, defaults))
                scopes(st.body, f"{prefix}{st.name}.<locals>.", False)
            else:
                for fld in ("body", "orelse", "finalbody", "handlers"):
                    inner = getattr(st, fld, None)
                    if isinstance(inner, list):
                        scopes([x for x in inner if isinstance(x, ast.stmt)] +
                               [y for h in inner if isinstance(h, ast.ExceptHandler) for y in h.body], prefix, in_class)

    for n in ast.walk(tree):
        if isinstance(n, ast.ImportFrom) and (n.module or n.level):
            for a in n.names:  # a relative import names the package's own module (``from . import names``)
                if a.name == "*":
                    if n.module:
                        mod.star.append(n.module)
                else:
                    mod.bind_import(a.asname or a.name, f"{n.module}.{a.name}" if n.module else a.name, n.lineno)
        elif isinstance(n, ast.Import):
            for a in n.names:
                mod.bind_import(a.asname or a.name.split(".")[0], a.name if a.asname else a.name.split(".")[0],
                                n.lineno)
        elif isinstance(n, ast.Call):
            mod.calls.append(call(n))
        elif isinstance(n, ast.Return) and n.value is not None:
            mod.returns.append((n.lineno, val(n.value)))
        elif isinstance(n, ast.ClassDef):
            mod.classes.append((n.name, n.lineno, getattr(n, "end_lineno", None) or n.lineno))
            mod.bases[n.name] = [d for d in (_dotted(b) for b in n.bases) if d]
        elif isinstance(n, ast.For) and isinstance(n.iter, ast.Call) and \
                (_dotted(n.iter.func) or "").rsplit(".", 1)[-1] in DISCOVERY:
            # for name, types in node.get_topic_names_and_types(): names found at run time (pyconst)
            for t in (n.target.elts if isinstance(n.target, ast.Tuple) else [n.target]):
                if isinstance(t, ast.Name):
                    mod.assigns.append((t.id, val(n.iter)))
        elif isinstance(n, (ast.Assign, ast.AnnAssign)) and n.value is not None:
            for t in (n.targets if isinstance(n, ast.Assign) else [n.target]):
                d = _dotted(t)
                if d is not None:
                    mod.assigns.append((d, val(n.value)))
                elif isinstance(t, ast.Tuple) and t.elts and isinstance(t.elts[0], ast.Name) and isinstance(
                        n.value, ast.Call) and (_dotted(n.value.func) or "").endswith(".parse_known_args"):
                    mod.assigns.append((t.elts[0].id, val(n.value)))  # args, rest = p.parse_known_args()
    if isinstance(tree, ast.Module):
        scopes(tree.body, "", False)
    mod.calls.sort(key=lambda c: (c.src.line, c.src.col))  # source order, as the tolerant reader gives
    return mod


def scan_python(text: str, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note]}`` for one file.

    A file that ``ast`` cannot parse is read by the tolerant reader, with one
    located ``ROS-PARSE`` warning naming the lines it could not read either."""
    try:
        tree = ast.parse(text, filename=shown)
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        from rclverify.ros.extract.sources_py_tolerant import tolerant_module
        line = getattr(exc, "lineno", None) or 1
        col = getattr(exc, "offset", None) or 1
        try:
            mod, unread = tolerant_module(text, shown)
        except RecursionError:
            mod, unread = None, "its nesting is too deep to read"
        why = f"not Python 3 ({getattr(exc, 'msg', exc)})"
        if mod is None:
            return {"nodes": [], "endpoints": [],
                    "notes": [Note(Src(shown, line, col), f"Python source does not parse: {why}; {unread}",
                                   "ROS-PARSE", "error")]}
        out = extract(mod, shown)
        out["notes"].insert(0, Note(Src(shown, line, col), f"Python source is {why}: read with the tolerant "
                                                           f"reader (tree-sitter-python); {unread}", "ROS-PARSE"))
        return out
    try:
        return extract(_ast_module(tree, shown), shown)
    except RecursionError:
        return {"nodes": [], "endpoints": [], "notes": [Note(Src(shown), "Python source nested too deeply to read",
                                                             "ROS-PARSE", "error")]}


def extract(mod: PyModule, shown: str) -> dict[str, Any]:
    """The record of a file from its :class:`PyModule` (either reader): nodes,
    endpoints, notes, ``owners`` and, for the linker (:mod:`link`), ``fns``,
    ``units``, ``calls``, ``fields``, ``consts``, ``node_names``, ``imports``."""
    sc = PyScope(mod, shown)
    ros2 = any(o.split(".")[0] == "rclpy" for o in mod.imports.values())
    out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": [], "lang": "py", "calls": [], "node_names": [],
                           "member_decls": [], "member_calls": [], "includes": [], "callbacks": {}, "ros2": ros2}
    said: set[str] = set()

    def type_of(v: Any, kind: str) -> tuple[str | None, Any]:
        """(type, candidates for the linker)."""
        if isinstance(v, str) or v is None:
            return v, None
        if v.kind == "call" and v.call is not None and v.call.func.split(".")[-1] == "numpy_msg" and v.call.args:
            return type_of(v.call.args[0], kind)
        if v.kind != "name":
            return None, None
        pv = sc.value(v)
        if pv is not None and pv[0] == "arg" and "." not in v.text:  # a helper's parameter: the callers' types
            return None, ("argtype", pv[1], pv[2])
        head = v.text.split(".")[0]
        chosen = {o for o, _ln in mod.import_lines.get(head, [])}
        if len(chosen) > 1 and head not in said:
            said.add(head)
            lines = sorted(ln for _o, ln in mod.import_lines[head])
            out["notes"].append(Note(v.src, f"'{head}' is imported {len(lines)} times (lines "
                                            f"{', '.join(map(str, lines))}), chosen at run time: read as "
                                            f"{mod.imports[head]}, the first (line {lines[0]})", "ROS-UNRESOLVED"))
        if head not in mod.imports and "." not in v.text and mod.star:
            want = "srv" if kind.startswith("service") else "action" if kind.startswith("action") else "msg"
            cands = sorted({t for m in mod.star if m.split(".")[-1] == ("msg" if want == "action" else want)
                            for t in [_typed(f"{m}.{v.text}", kind)] if t is not None})
            if len(cands) == 1:
                return cands[0], None
            return None, (("cands", tuple(cands)) if cands else None)
        return _typed(sc.full(v.text), kind), None

    def add(kind: str, name: Any, type_v: Any, c: PyCall, handle: Any = None) -> None:
        if isinstance(name, tuple) and name and name[0] == "under":
            nv = sc.value(name[1]) if name[1] is not None else None
            val, written, nsrc = symbols.cat([nv, symbols.lit("/" + name[2])]) if nv is not None else None, \
                (name[1].text if name[1] is not None else "?") + "/" + name[2], c.src
        elif isinstance(name, PyVal):
            val, written, nsrc = sc.value(name), name.text, name.src
        else:
            val, written, nsrc = name, symbols.text(name) or "?", c.src
        t, cands = type_of(type_v, kind)
        unit = sc.unit_at(c.src.line)
        ep, note = emit.make(kind, val, handle, t, c.src, unit, sc.fn_key(c.src.line), written, nsrc, cands)
        if note is not None:
            out["notes"].append(note)
        if ep is None:
            return
        if ep.pending is None and t is None and isinstance(type_v, PyVal):
            out["notes"].append(Note(type_v.src, f"type '{_short(type_v.text)}' of {_WHAT[kind]} "
                                                 f"'{ep.topic or ep.param}' not resolved statically"))
        out["endpoints"].append(ep)

    for c in mod.calls:
        f = sc.full(c.func) if c.func else ""
        last = c.func.rsplit(".", 1)[-1]
        if f in ("rospy.init_node", "rclpy.create_node", "rclpy.node.Node") or c.func == "super().__init__":
            v = c.args[0] if c.args else c.kwargs.get("name") or c.kwargs.get("node_name")
            if v is None:
                continue
            val = sc.value(v)
            if c.func == "super().__init__" and v.kind != "str" and not _node_class(mod, sc.class_at(c.src.line)):
                continue
            unit = sc.unit_at(c.src.line)
            if val is not None and val[0] == "str" and names.node_name_problem(val[1]) is not None:
                out["notes"].append(Note(v.src, f"node name {names.node_name_problem(val[1])}: not resolved "
                                                f"statically; its endpoints are not in the graph"))
                continue
            if val is not None and val[0] == "str":
                out["nodes"].append((val[1], c.src))
            elif symbols.is_concrete(val):
                if c.func != "super().__init__":
                    out["notes"].append(Note(v.src, "node name is not a string literal: not resolved statically"))
                continue
            life = "lifecycle" if _node_class(mod, sc.class_at(c.src.line), lifecycle=sc.full) else None
            ns = c.kwargs.get("namespace")  # rclpy: keyword-only (Node, create_node); rospy has none
            nsv = (sc.value(ns) or ("runtime", "computed at run time")) if ns else None
            out["node_names"].append((val, c.src, unit, sc.fn_key(c.src.line), nsv, life))
            continue
        spec = _CTORS.get(f)
        if spec is None and "actionlib" in f and last in _CTORS:
            spec = _CTORS[last]
        if spec is None and f.startswith("rclpy.action") and last in ("ActionServer", "ActionClient"):
            spec = _CTORS[f"rclpy.{last}"]
        if spec is None and "." in c.func and last in _METHODS and not f.startswith(("rospy.", "os.")):
            spec = _METHODS[last]
        if spec is None:
            helped = py_helpers.helper(f, c, ros2) if f and "." in f else None
            for m in mod.star if helped is None and f and "." not in f and f not in mod.imports else ():
                helped = helped or py_helpers.helper(f"{m}.{f}", c, ros2)  # from interactive_markers... import *
            if helped is not None:
                for kind, name, typ in helped:
                    add(kind, name, typ, c)
                continue
            callee = sc.callee(c)
            if callee is not None:
                out["calls"].append(("call", callee, [sc.value(a) for a in c.args], sc.fn_key(c.src.line),
                                     sc.unit_at(c.src.line), c.src, {k: sc.value(v) for k, v in c.kwargs.items()}))
            continue
        kind, ni, nk, ti, tk = spec
        name_v = c.kwargs.get(nk) or (c.args[ni] if len(c.args) > ni else None)
        type_v = c.kwargs.get(tk) or (c.args[ti] if len(c.args) > ti else None)
        if name_v is not None:
            add(kind, name_v, type_v, c)
    out["owners"] = owners(mod.classes, out["nodes"], out["endpoints"])
    out["fns"] = {f"{shown}::{q}": (sc.unit_at(a), params, [], [sc.value(d) for d in defaults])
                  for q, a, _b, params, defaults in mod.functions}
    out["units"] = {f"{shown}::{q}": {"bases": mod.bases.get(q.split(".")[-1], []), "members": {}}
                    for q, _a, _b in sc.cls}
    out["fields"] = sc.fields()
    out["consts"] = sc.consts()
    out["returns"] = sc.returns()
    out["imports"] = sorted(set(mod.imports.values()) | set(mod.star))
    return out


def _typed(dotted: str, kind: str) -> str | None:
    """``pkg.msg.T`` -> ``pkg/msg/T`` (or the service's, the action's) for role ``kind``."""
    parts = dotted.split(".")
    if len(parts) < 3 or parts[-2] not in ("msg", "srv", "action"):
        return None
    d = "/".join(parts[-3:])
    if kind.startswith("service"):
        return service_type(d)
    if kind.startswith("action"):
        return action_type(d)
    t = canon_type(d)
    return t if t and parts[-2] == "msg" else None


def _node_class(mod: PyModule, cls: str | None, depth: int = 0, lifecycle: Any = None) -> bool:
    """Whether class ``cls`` of the file derives from rclpy's ``Node`` (directly or
    through a class of the same file); with ``lifecycle`` (the file's import
    resolver), whether from a lifecycle node (``rclpy.lifecycle.Node``,
    ``LifecycleNode``)."""
    if cls is None or depth > 5:
        return False
    for b in mod.bases.get(cls.split(".")[-1], []):
        if lifecycle is not None and (b.split(".")[-1] == "LifecycleNode" or ".lifecycle." in lifecycle(b) + "."
                                      and b.split(".")[-1] == "Node"):
            return True
        if lifecycle is None and b.split(".")[-1] in ("Node", "LifecycleNode") or \
                _node_class(mod, b, depth + 1, lifecycle):
            return True
    return False


def owners(classes: list[tuple[str, int, int]], nodes: list[tuple[str, Src]], eps: list[Endpoint]) -> list[int]:
    """For each endpoint, the index in ``nodes`` of the node it belongs to.

    A file that names several nodes, each in its own class (``class
    Talker(Node)`` with ``super().__init__('talker')``), gives each node the
    endpoints written inside its class (the innermost class holding the call,
    ``classes`` as ``(name, first line, last line)``); endpoints outside every
    such class belong to the first node named outside them (``create_node``
    in ``main``), else to the first node. Returns ``[]`` when the file names
    fewer than two distinct nodes (every endpoint is the one node's)."""
    if len({n for n, _ in nodes}) < 2:
        return []

    def cls(line: int) -> tuple[str, int, int] | None:
        inside = [c for c in classes if c[1] <= line <= c[2]]
        return min(inside, key=lambda c: c[2] - c[1]) if inside else None

    of_class: dict[tuple[str, int, int], int] = {}
    loose = None
    for i, (_name, src) in enumerate(nodes):
        c = cls(src.line)
        if c is not None:
            of_class.setdefault(c, i)
        elif loose is None:
            loose = i
    out = []
    for e in eps:
        c = cls(e.src.line)
        while c is not None and c not in of_class:  # a nested class: look outwards
            outer = [k for k in classes if k[1] <= c[1] and k[2] >= c[2] and k != c]
            c = min(outer, key=lambda k: k[2] - k[1]) if outer else None
        out.append(of_class[c] if c is not None else (loose if loose is not None else 0))
    return out
