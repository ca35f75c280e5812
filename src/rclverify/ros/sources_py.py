"""Publishers, subscribers and node names in Python node sources, read with
Python's ``ast`` (the code is never imported or run).

Recognised (rospy API, ROS 1; rclpy API, ROS 2):

* ``rospy.Publisher(name, data_class, ...)``, ``rospy.Subscriber(name, data_class, ...)``
  (also imported bare, and as keywords ``name=``/``data_class=``);
* ``<x>.create_publisher(msg_type, topic, ...)``, ``<x>.create_subscription(msg_type, topic, ...)``;
* node names from ``rospy.init_node('n')``, ``rclpy.create_node('n')``,
  ``Node('n')`` and ``super().__init__('n')`` / ``super().__init__(node_name='n')``.

A topic name that is not a string literal (a variable, a parameter, an
expression) is reported unresolved at its location, never guessed.
"""
from __future__ import annotations

import ast
from typing import Any

from .model import Endpoint, Note, Src, canon_type

_ROSPY = {"Publisher": "pub", "Subscriber": "sub"}
_RCLPY = {"create_publisher": "pub", "create_subscription": "sub"}


def _dotted(e: ast.AST) -> str | None:
    if isinstance(e, ast.Name):
        return e.id
    if isinstance(e, ast.Attribute):
        base = _dotted(e.value)
        return f"{base}.{e.attr}" if base else None
    return None


def _str(e: ast.AST | None) -> str | None:
    return e.value if isinstance(e, ast.Constant) and isinstance(e.value, str) else None


def scan_python(text: str, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note]}`` for one file.

    A file that does not parse gives one located ``ROS-PARSE`` error note."""
    out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": []}
    try:
        tree = ast.parse(text, filename=shown)
    except (SyntaxError, ValueError, RecursionError, MemoryError) as exc:
        line = getattr(exc, "lineno", None) or 1
        col = getattr(exc, "offset", None) or 1
        out["notes"].append(Note(Src(shown, line, col), f"Python source does not parse: {getattr(exc, 'msg', exc)}",
                                 "ROS-PARSE", "error"))
        return out
    imports: dict[str, str] = {}  # local name -> dotted origin
    for n in ast.walk(tree):
        if isinstance(n, ast.ImportFrom) and n.module:
            for a in n.names:
                imports[a.asname or a.name] = f"{n.module}.{a.name}"
        elif isinstance(n, ast.Import):
            for a in n.names:
                imports[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]

    def full(e: ast.AST | None) -> str | None:
        d = _dotted(e) if e is not None else None
        if d is None:
            return None
        head, _, rest = d.partition(".")
        base = imports.get(head, head)
        return f"{base}.{rest}" if rest else base

    def msg_type(e: ast.AST | None) -> str | None:
        d = full(e)
        if d is None:
            return None
        parts = d.split(".")
        if len(parts) >= 3 and parts[-2] in ("msg", "srv", "action"):
            return canon_type("/".join(parts[-3:]))
        return None

    def arg(call: ast.Call, pos: int, kw: tuple[str, ...]) -> ast.AST | None:
        for k in call.keywords:
            if k.arg in kw:
                return k.value
        return call.args[pos] if len(call.args) > pos else None

    def loc(e: ast.AST) -> Src:
        return Src(shown, getattr(e, "lineno", 1), getattr(e, "col_offset", 0) + 1)

    for call in ast.walk(tree):
        if not isinstance(call, ast.Call):
            continue
        fn = full(call.func) or ""
        attr = call.func.attr if isinstance(call.func, ast.Attribute) else (call.func.id if isinstance(call.func, ast.Name) else "")
        kind = None
        if fn in ("rospy.Publisher", "rospy.Subscriber"):
            kind = _ROSPY[fn.split(".")[1]]
            name_e, type_e = arg(call, 0, ("name",)), arg(call, 1, ("data_class",))
        elif attr in _RCLPY and isinstance(call.func, ast.Attribute):
            kind = _RCLPY[attr]
            type_e, name_e = arg(call, 0, ("msg_type",)), arg(call, 1, ("topic",))
        elif fn in ("rospy.init_node", "rclpy.create_node", "rclpy.node.Node") or (
                isinstance(call.func, ast.Attribute) and attr == "__init__"
                and isinstance(call.func.value, ast.Call) and _dotted(call.func.value.func) == "super"):
            name_e = arg(call, 0, ("name", "node_name"))
            name = _str(name_e)
            if name is not None:
                out["nodes"].append((name, loc(call)))
            elif name_e is not None and fn != "" and attr != "__init__":
                out["notes"].append(Note(loc(name_e), "node name is not a string literal: not resolved statically"))
            continue
        if kind is None:
            continue
        topic = _str(name_e)
        t = msg_type(type_e)
        where = loc(call)
        if topic is None:
            what = ast.unparse(name_e) if name_e is not None else "nothing"
            out["notes"].append(Note(loc(name_e) if name_e is not None else where,
                                     f"{'publisher' if kind == 'pub' else 'subscriber'} topic name is "
                                     f"'{what}', not a string literal: not resolved statically"))
            continue
        if t is None and type_e is not None:
            out["notes"].append(Note(loc(type_e), f"message type '{ast.unparse(type_e)}' of topic "
                                                  f"'{topic}' not resolved statically"))
        out["endpoints"].append(Endpoint(kind, topic, t, where))
    return out
