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
* for the linker: functions and their parameters, classes and their bases, the calls of the
  package's own classes and functions with their argument values (a
  ``super().__init__(...)`` of a class deriving from one of the package's is
  a call of that base's constructor), attribute bindings, module constants,
  imports.

A name that is not read statically is reported unresolved at its location,
never guessed.
"""
from __future__ import annotations

import ast
from typing import Any

from rclverify.ros.extract import emit, names, py_helpers, symbols
from rclverify.ros.extract.cpp_types import action_type, service_type
from rclverify.ros.extract.model import Endpoint, Note, Src, canon_type
from rclverify.ros.extract.pyconst import _ROS, PyScope
from rclverify.ros.extract.pyrecords import PyCall, PyModule, PyVal
from rclverify.ros.extract.sources_py_ast import ast_module


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


def scan_python(text: str, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note]}`` for one file.

    A file that ``ast`` cannot parse is read by the tolerant reader, with one
    located ``ROS-PARSE`` warning naming the lines it could not read either."""
    try:
        tree = ast.parse(text, filename=shown)
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        from rclverify.ros.extract.sources_py_tolerant import tolerant_module  # deferred: optional or conditional (inside a block)
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
        return extract(ast_module(tree, shown), shown)
    except RecursionError:
        return {"nodes": [], "endpoints": [], "notes": [Note(Src(shown), "Python source nested too deeply to read",
                                                             "ROS-PARSE", "error")]}


def extract(mod: PyModule, shown: str) -> dict[str, Any]:
    """The record of a file from its :class:`PyModule` (either reader): nodes,
    endpoints, notes, ``owners`` and, for the linker (:mod:`link`), ``fns``,
    ``units``, ``calls``, ``fields``, ``consts``, ``node_names``, ``imports``."""
    x = _Extractor(mod, shown)
    for c in mod.calls:
        x.call(c)
    return x.finish()


class _Extractor:
    """One file's record built call by call (:func:`extract`)."""

    def __init__(self, mod: PyModule, shown: str) -> None:
        self.mod, self.shown = mod, shown
        self.sc = PyScope(mod, shown)
        self.ros2 = any(o.split(".")[0] == "rclpy" for o in mod.imports.values())
        self.out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": [], "lang": "py", "calls": [],
                                    "node_names": [], "member_decls": [], "member_calls": [], "includes": [],
                                    "callbacks": {}, "ros2": self.ros2}
        self.said: set[str] = set()

    def type_of(self, v: Any, kind: str) -> tuple[str | None, Any]:
        """(type, candidates for the linker)."""
        mod, sc, out = self.mod, self.sc, self.out
        if isinstance(v, str) or v is None:
            return v, None
        if v.kind == "call" and v.call is not None and v.call.func.split(".")[-1] == "numpy_msg" and v.call.args:
            return self.type_of(v.call.args[0], kind)
        if v.kind != "name":
            return None, None
        pv = sc.value(v)
        if pv is not None and pv[0] == "arg" and "." not in v.text:  # a helper's parameter: the callers' types
            return None, ("argtype", pv[1], pv[2])
        head = v.text.split(".")[0]
        chosen = {o for o, _ln in mod.import_lines.get(head, [])}
        if len(chosen) > 1 and head not in self.said:
            self.said.add(head)
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

    def add(self, kind: str, name: Any, type_v: Any, c: PyCall, handle: Any = None) -> None:
        """The endpoint of role ``kind`` named by ``name`` with type ``type_v``, made at call ``c``."""
        sc, out = self.sc, self.out
        if isinstance(name, tuple) and name and name[0] == "under":
            nv = sc.value(name[1]) if name[1] is not None else None
            val, written, nsrc = symbols.cat([nv, symbols.lit("/" + name[2])]) if nv is not None else None, \
                (name[1].text if name[1] is not None else "?") + "/" + name[2], c.src
        elif isinstance(name, PyVal):
            val, written, nsrc = sc.value(name), name.text, name.src
        else:
            val, written, nsrc = name, symbols.text(name) or "?", c.src
        t, cands = self.type_of(type_v, kind)
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

    def call(self, c: PyCall) -> None:
        """One call: a node's name, an endpoint's constructor or method, a
        library helper, or a call of the package's own code (for the linker)."""
        sc = self.sc
        f = sc.full(c.func) if c.func else ""
        last = c.func.rsplit(".", 1)[-1]
        if f in ("rospy.init_node", "rclpy.create_node", "rclpy.node.Node") or c.func == "super().__init__":
            if c.func == "super().__init__":
                self.base_init(c)
            self.node_name(c)
            return
        spec = _CTORS.get(f)
        if spec is None and "actionlib" in f and last in _CTORS:
            spec = _CTORS[last]
        if spec is None and f.startswith("rclpy.action") and last in ("ActionServer", "ActionClient"):
            spec = _CTORS[f"rclpy.{last}"]
        if spec is None and "." in c.func and last in _METHODS and not f.startswith(("rospy.", "os.")):
            spec = _METHODS[last]
        if spec is None:
            self.other_call(c, f)
            return
        kind, ni, nk, ti, tk = spec
        name_v = c.kwargs.get(nk) or (c.args[ni] if len(c.args) > ni else None)
        type_v = c.kwargs.get(tk) or (c.args[ti] if len(c.args) > ti else None)
        if name_v is not None:
            self.add(kind, name_v, type_v, c)

    def base_init(self, c: PyCall) -> None:
        """``super().__init__(...)`` in a class whose first base is a class of this
        file or one it imports from outside ROS (``class Arm(Joint)``): a call of
        that base's constructor, for the linker, which runs the base's code (its
        endpoints) with these arguments when the package holds it."""
        mod, sc = self.mod, self.sc
        cls = sc.class_at(c.src.line)
        bases = mod.bases.get(cls.split(".")[-1], []) if cls else []
        if not bases or bases[0].split(".")[-1] in ("Node", "LifecycleNode"):
            return
        b = bases[0]
        if any(q == b for q, _a, _b in sc.cls):
            callee = f"{self.shown}::{b}"
        elif b.split(".")[0] in mod.imports and sc.full(b).split(".")[0] not in _ROS:
            callee = f"ext:{sc.full(b)}"
        else:
            return
        self.out["calls"].append(("call", callee, [sc.value(a) for a in c.args], sc.fn_key(c.src.line),
                                  sc.unit_at(c.src.line), c.src, {k: sc.value(v) for k, v in c.kwargs.items()}))

    def node_name(self, c: PyCall) -> None:
        """``rospy.init_node(n)``, ``rclpy.create_node(n)``, ``Node(n)``, ``super().__init__(n)``."""
        mod, sc, out = self.mod, self.sc, self.out
        v = c.args[0] if c.args else c.kwargs.get("name") or c.kwargs.get("node_name")
        if v is None:
            return
        val = sc.value(v)
        if c.func == "super().__init__" and v.kind != "str" and not _node_class(mod, sc.class_at(c.src.line)):
            return
        unit = sc.unit_at(c.src.line)
        if val is not None and val[0] == "str" and names.node_name_problem(val[1]) is not None:
            out["notes"].append(Note(v.src, f"node name {names.node_name_problem(val[1])}: not resolved "
                                            f"statically; its endpoints are not in the graph"))
            return
        if val is not None and val[0] == "str":
            out["nodes"].append((val[1], c.src))
        elif symbols.is_concrete(val):
            if c.func != "super().__init__":
                out["notes"].append(Note(v.src, "node name is not a string literal: not resolved statically"))
            return
        life = "lifecycle" if _node_class(mod, sc.class_at(c.src.line), lifecycle=sc.full) else None
        ns = c.kwargs.get("namespace")  # rclpy: keyword-only (Node, create_node); rospy has none
        nsv = (sc.value(ns) or ("runtime", "computed at run time")) if ns else None
        out["node_names"].append((val, c.src, unit, sc.fn_key(c.src.line), nsv, life))

    def other_call(self, c: PyCall, f: str) -> None:
        """A call that makes no endpoint itself: a library helper's endpoints
        (:mod:`py_helpers`), else a call of the package's own code."""
        mod, sc = self.mod, self.sc
        helped = py_helpers.helper(f, c, self.ros2) if f and "." in f else None
        for m in mod.star if helped is None and f and "." not in f and f not in mod.imports else ():
            helped = helped or py_helpers.helper(f"{m}.{f}", c, self.ros2)  # from interactive_markers... import *
        if helped is not None:
            for kind, name, typ in helped:
                self.add(kind, name, typ, c)
            return
        callee = sc.callee(c)
        if callee is not None:
            self.out["calls"].append(("call", callee, [sc.value(a) for a in c.args], sc.fn_key(c.src.line),
                                      sc.unit_at(c.src.line), c.src, {k: sc.value(v) for k, v in c.kwargs.items()}))

    def finish(self) -> dict[str, Any]:
        """The record with what the linker reads of the file."""
        mod, sc, out, shown = self.mod, self.sc, self.out, self.shown
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
