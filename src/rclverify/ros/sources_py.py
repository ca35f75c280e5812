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
* a name held in a variable or attribute (``self.topic = ...``), a literal or a
  parameter: ``rospy.get_param('~topic', 'default')`` (the name as written:
  ``~`` private, else relative), rclpy ``declare_parameter('topic', 'default')``
  with ``get_parameter('topic')...`` (ROS 2 parameters are the node's: ``~topic``);
* node names from ``rospy.init_node('n')``, ``rclpy.create_node('n')``,
  ``Node('n')`` and ``super().__init__('n')`` / ``super().__init__(node_name='n')``.

A name that is neither a literal nor a parameter is reported unresolved at
its location, never guessed.
"""
from __future__ import annotations

import ast
from typing import Any

from .model import Endpoint, Note, Src, canon_type
from .pyrecords import PyCall, PyModule, PyVal
from .sources_cpp import action_type, service_type


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
            "create_subscription": ("sub", 1, "topic", 0, "msg_type"),
            "create_service": ("service_servers", 1, "srv_name", 0, "srv_type"),
            "create_client": ("service_clients", 1, "srv_name", 0, "srv_type")}
_WHAT = {"pub": "publisher topic", "sub": "subscriber topic", "service_servers": "service server",
         "service_clients": "service client", "action_servers": "action server", "action_clients": "action client"}


def _short(text: str, limit: int = 80) -> str:
    """Source text quoted in a note, cut to ``limit`` characters."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


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

    for n in ast.walk(tree):
        if isinstance(n, ast.ImportFrom) and n.module:
            for a in n.names:
                mod.imports[a.asname or a.name] = f"{n.module}.{a.name}"
        elif isinstance(n, ast.Import):
            for a in n.names:
                mod.imports[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
        elif isinstance(n, ast.Call):
            mod.calls.append(call(n))
        elif isinstance(n, ast.ClassDef):
            mod.classes.append((n.name, n.lineno, getattr(n, "end_lineno", None) or n.lineno))
        elif isinstance(n, (ast.Assign, ast.AnnAssign)) and n.value is not None:
            for t in (n.targets if isinstance(n, ast.Assign) else [n.target]):
                d = _dotted(t)
                if d is not None:
                    mod.assigns.append((d, val(n.value)))
    mod.calls.sort(key=lambda c: (c.src.line, c.src.col))  # source order, as the tolerant reader gives
    return mod


def scan_python(text: str, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note]}`` for one file.

    A file that ``ast`` cannot parse is read by the tolerant reader, with one
    located ``ROS-PARSE`` warning naming the lines it could not read either."""
    try:
        tree = ast.parse(text, filename=shown)
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        from .sources_py_tolerant import tolerant_module
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
    """Nodes, endpoints and notes from a file's :class:`PyModule` (either reader)."""
    out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": []}

    def full(d: str) -> str:
        head, _, rest = d.partition(".")
        base = mod.imports.get(head, head)
        return f"{base}.{rest}" if rest else base

    def type_of(v: PyVal | None, kind: str) -> str | None:
        if v is None or v.kind != "name":
            return None
        parts = full(v.text).split(".")
        if len(parts) < 3 or parts[-2] not in ("msg", "srv", "action"):
            return None
        dotted = "/".join(parts[-3:])
        if kind.startswith("service"):
            return service_type(dotted)
        if kind.startswith("action"):
            return action_type(dotted)
        t = canon_type(dotted)
        return t if t and parts[-2] == "msg" else None

    declared: dict[str, str | None] = {}
    for c in mod.calls:
        if c.func.endswith("declare_parameter") and c.args and c.args[0].kind == "str":
            d = c.args[1] if len(c.args) > 1 else c.kwargs.get("value")
            declared.setdefault("~" + c.args[0].text.lstrip("~"), d.text if d is not None and d.kind == "str" else None)
    binds: dict[str, list[PyVal]] = {}
    for t, v in mod.assigns:
        binds.setdefault(t, []).append(v)

    def getter(c: PyCall) -> tuple[str | None, str] | None:
        f = full(c.func) if c.func else ""
        if not c.args or c.args[0].kind != "str":
            return None
        name = c.args[0].text
        if f in ("rospy.get_param", "rospy.client.get_param"):
            d = c.args[1] if len(c.args) > 1 else c.kwargs.get("default")
            return (d.text if d is not None and d.kind == "str" else None), name
        last = c.func.rsplit(".", 1)[-1]
        if last in ("get_parameter", "declare_parameter", "get_parameter_or"):
            p = "~" + name.lstrip("~")
            d = c.args[1] if last != "get_parameter" and len(c.args) > 1 else None
            return (d.text if d is not None and d.kind == "str" else declared.get(p)), p
        return None

    def resolve(v: PyVal, depth: int = 0) -> tuple[str | None, str | None]:
        if v.kind == "str":
            return v.text, None
        if v.kind == "name" and depth < 5:
            vs = binds.get(v.text, [])
            got = {resolve(x, depth + 1) for x in vs}
            return next(iter(got)) if len(got) == 1 else (None, None)
        for c in ([v.call] if v.call else []) + v.calls:
            g = getter(c)
            if g is not None:
                return g
        return None, None

    for c in mod.calls:
        f = full(c.func) if c.func else ""
        last = c.func.rsplit(".", 1)[-1]
        if f in ("rospy.init_node", "rclpy.create_node", "rclpy.node.Node") or c.func == "super().__init__":
            v = c.args[0] if c.args else c.kwargs.get("name") or c.kwargs.get("node_name")
            if v is not None and v.kind == "str":
                out["nodes"].append((v.text, c.src))
            elif v is not None and c.func != "super().__init__":
                out["notes"].append(Note(v.src, "node name is not a string literal: not resolved statically"))
            continue
        spec = _CTORS.get(f)
        if spec is None and "actionlib" in f and last in _CTORS:
            spec = _CTORS[last]
        if spec is None and f.startswith("rclpy.action") and last in ("ActionServer", "ActionClient"):
            spec = _CTORS[f"rclpy.{last}"]
        if spec is None and "." in c.func and last in _METHODS:
            spec = _METHODS[last]
        if spec is None:
            continue
        kind, ni, nk, ti, tk = spec
        name_v = c.kwargs.get(nk) or (c.args[ni] if len(c.args) > ni else None)
        type_v = c.kwargs.get(tk) or (c.args[ti] if len(c.args) > ti else None)
        if name_v is None:
            continue
        topic, param = resolve(name_v)
        if topic is None and param is None:
            out["notes"].append(Note(name_v.src, f"{_WHAT[kind]} name is '{_short(name_v.text)}', not a string literal: "
                                                 f"not resolved statically"))
            continue
        t = type_of(type_v, kind)
        if t is None and type_v is not None:
            out["notes"].append(Note(type_v.src, f"type '{_short(type_v.text)}' of {_WHAT[kind]} '{topic or param}' "
                                                 f"not resolved statically"))
        out["endpoints"].append(Endpoint(kind, topic or "", t, c.src, param))
    out["owners"] = owners(mod.classes, out["nodes"], out["endpoints"])
    return out


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
