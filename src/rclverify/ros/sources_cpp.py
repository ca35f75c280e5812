"""Publishers, subscribers and node names in C++ node sources, read with
tree-sitter's C++ grammar (``tree-sitter``, ``tree-sitter-cpp``).

Recognised (roscpp, ROS 1; rclcpp, ROS 2):

* ``<h>.advertise<T>(topic, ...)``, ``<h>.subscribe<T>(topic, ...)`` and
  ``<h>.subscribe(topic, n, cb)`` (the type then comes from the callback's
  first parameter, ``const pkg::T::ConstPtr&``, when ``cb`` is a function of
  the same file);
* ``create_publisher<T>(topic, ...)``, ``create_subscription<T>(topic, ...)``
  (bare, ``this->``, ``node->``, ``node.``);
* node names from ``ros::init(argc, argv, "n")``, ``rclcpp::Node("n")``,
  ``Node("n")`` member initialisers and ``std::make_shared<rclcpp::Node>("n")``.

A topic name that is not a string literal is reported unresolved at its location.
"""
from __future__ import annotations

from typing import Any

from .model import Endpoint, Note, Src, canon_type

_CALLS = {"advertise": "pub", "subscribe": "sub", "create_publisher": "pub", "create_subscription": "sub"}
_PARSER: Any = None


def _parser() -> Any:
    global _PARSER
    if _PARSER is None:
        import tree_sitter_cpp
        from tree_sitter import Language, Parser
        _PARSER = Parser(Language(tree_sitter_cpp.language()))
    return _PARSER


def _txt(n: Any) -> str:
    return n.text.decode("utf-8", errors="replace") if n is not None else ""


def _string(n: Any) -> str | None:
    if n is None or n.type != "string_literal":
        return None
    parts = [c for c in n.children if c.type == "string_content"]
    if any(c.type == "escape_sequence" for c in n.children):
        return None
    return _txt(parts[0]) if parts else ""


def _walk(n: Any):  # type: ignore[no-untyped-def]
    stack = [n]
    while stack:
        x = stack.pop()
        yield x
        stack.extend(reversed(x.children))


def scan_cpp(data: bytes, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note]}`` for one file.

    tree-sitter recovers from syntax errors, so a broken file still yields
    what it can; its ERROR regions are reported as one located warning."""
    out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": []}
    tree = _parser().parse(data)
    root = tree.root_node

    def src(n: Any) -> Src:
        return Src(shown, n.start_point[0] + 1, n.start_point[1] + 1)

    callbacks: dict[str, str] = {}
    for n in _walk(root):
        if n.type == "function_declarator":
            name = _txt(n.child_by_field_name("declarator")).split("::")[-1]
            params = n.child_by_field_name("parameters")
            first = next((c for c in (params.children if params else []) if c.type == "parameter_declaration"), None)
            if first is not None and first.child_by_field_name("type") is not None:
                t = canon_type(_txt(first.child_by_field_name("type")))
                if t and t.count("/") == 2:
                    callbacks[name] = t
    if root.has_error:
        err = next((n for n in _walk(root) if n.type == "ERROR" or n.is_missing), root)
        out["notes"].append(Note(src(err), "C++ source has syntax errors; read what tree-sitter recovered",
                                 "ROS-PARSE"))
    for n in _walk(root):
        if n.type == "field_initializer":
            fid = next((c for c in n.children if c.type == "field_identifier"), None)
            args = next((c for c in n.children if c.type == "argument_list"), None)
            if fid is not None and _txt(fid) in ("Node", "rclcpp::Node") and args is not None:
                s = _string(args.named_children[0]) if args.named_children else None
                if s is not None:
                    out["nodes"].append((s, src(n)))
            continue
        if n.type != "call_expression":
            continue
        fn = n.child_by_field_name("function")
        args_n = n.child_by_field_name("arguments")
        args = list(args_n.named_children) if args_n is not None else []
        name, targs = None, None
        if fn is None:
            continue
        f = fn
        if f.type == "field_expression":
            f = f.child_by_field_name("field")
        if f is not None and f.type in ("template_method", "template_function"):
            name = _txt(f.child_by_field_name("name"))
            targs = f.child_by_field_name("arguments")
        elif f is not None:
            name = _txt(f)
        name_last = (name or "").split("::")[-1]
        full = _txt(fn)
        if full in ("ros::init",) and len(args) >= 3:
            s = _string(args[2])
            if s is not None:
                out["nodes"].append((s, src(n)))
            else:
                out["notes"].append(Note(src(args[2]), "node name is not a string literal: not resolved statically"))
            continue
        if name_last == "make_shared" and targs is not None and "Node" in _txt(targs) and args:
            s = _string(args[0])
            if s is not None:
                out["nodes"].append((s, src(n)))
            continue
        kind = _CALLS.get(name_last)
        if kind is None or not args:
            continue
        msg_type = None
        if targs is not None and targs.named_children:
            msg_type = canon_type(_txt(targs.named_children[0]))
        elif kind == "sub" and name_last == "subscribe" and len(args) >= 3:
            cb = _txt(args[2]).lstrip("&").split("::")[-1]
            msg_type = callbacks.get(cb)
        topic = _string(args[0])
        what = "publisher" if kind == "pub" else "subscriber"
        if topic is None:
            out["notes"].append(Note(src(args[0]), f"{what} topic name is '{_txt(args[0])}', not a string "
                                                   f"literal: not resolved statically"))
            continue
        if msg_type is None:
            out["notes"].append(Note(src(n), f"message type of {what} on '{topic}' not resolved statically"))
        out["endpoints"].append(Endpoint(kind, topic, msg_type, src(n)))
    return out
