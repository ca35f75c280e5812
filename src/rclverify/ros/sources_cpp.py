"""Publishers, subscribers, services, actions and node names in C++ node
sources, read with tree-sitter's C++ grammar (``tree-sitter``, ``tree-sitter-cpp``).

Recognised (roscpp and actionlib, ROS 1; rclcpp and rclcpp_action, ROS 2):

* ``<h>.advertise<T>(topic, ...)``, ``<h>.subscribe<T>(topic, ...)`` and
  ``<h>.subscribe(topic, n, cb)`` (the type then comes from the callback's
  first parameter, ``const pkg::T::ConstPtr&``, when ``cb`` is a function of
  the same file); ``create_publisher<T>``, ``create_subscription<T>`` with any
  receiver (bare, ``this->``, ``node_->``, ``shared_from_this()->``, ``node.``);
* services: ``advertiseService(name, &cb)`` (type from ``cb``'s
  ``pkg::Srv::Request&``), ``serviceClient<Srv>(name)``, ``create_service<Srv>``,
  ``create_client<Srv>``; actions: ``actionlib::SimpleActionServer<pkg::XAction>``
  / ``SimpleActionClient`` (declared with arguments, as members initialised in
  a constructor, through ``new`` or ``make_shared``), ``rclcpp_action::create_server<T>``
  / ``create_client<T>``; ``using``/``typedef`` aliases of the type are followed;
* names held in variables or members: string literals, and parameters
  (:mod:`cpp_params`): roscpp ``param``/``getParam``, rclcpp
  ``declare_parameter``/``get_parameter``; a ``ros::NodeHandle pnh("~")``
  makes the names created through it private;
* export/visibility macros before a class name (``class MY_PUBLIC Talker :``)
  are blanked before parsing (same length, so locations stay);
* node names from ``ros::init(argc, argv, "n")``, ``Node("n")`` member
  initialisers, ``std::make_shared<rclcpp::Node>("n")``, ``rclcpp::Node::make_shared("n")``;
* which class each endpoint and node name belongs to (``classes``), and the
  classes registered as components (``RCLCPP_COMPONENTS_REGISTER_NODE(ns::C)``).

A name that is not read statically is reported unresolved at its location.
"""
from __future__ import annotations

import re
from typing import Any

from .cpp_params import Bindings, string_value
from . import treesitter
from .model import Endpoint, Note, Src, canon_type

_CALLS = {"advertise": "pub", "subscribe": "sub", "create_publisher": "pub", "create_subscription": "sub",
          "advertiseService": "service_servers", "serviceClient": "service_clients",
          "create_service": "service_servers", "create_client": "service_clients",
          "create_server": "action_servers"}
_ACTIONLIB = {"SimpleActionServer": "action_servers", "ActionServer": "action_servers",
              "SimpleActionClient": "action_clients", "ActionClient": "action_clients"}
_NODE_TYPES = ("Node", "rclcpp::Node", "LifecycleNode", "rclcpp_lifecycle::LifecycleNode")
_WHAT = {"pub": "publisher topic", "sub": "subscriber topic", "service_servers": "service server",
         "service_clients": "service client", "action_servers": "action server", "action_clients": "action client"}
_MACRO = re.compile(rb"\b(?:class|struct)\s+((?:[A-Z][A-Z0-9_]*[A-Z0-9]\s+)+)(?=[A-Za-z_]\w*\s*(?:final\s*)?[:{])")
_REGISTER = re.compile(rb"\bRCLCPP_COMPONENTS_REGISTER_NODE\s*\(\s*([A-Za-z_][\w:]*)\s*\)")


def _walk(n: Any):  # type: ignore[no-untyped-def]
    stack = [n]
    while stack:
        x = stack.pop()
        yield x
        stack.extend(reversed(x.children))


def blank_macros(data: bytes) -> bytes:
    """``class API Name :`` -> ``class     Name :``: upper-case macro words between
    ``class``/``struct`` and the class name become spaces (offsets unchanged)."""
    return _MACRO.sub(lambda m: m.group(0)[: m.start(1) - m.start(0)] + b" " * len(m.group(1)), data)


def action_type(name: str | None) -> str | None:
    """``pkg::FibonacciAction`` / ``pkg/msg/FibonacciAction`` (ROS 1 actionlib's
    generated message) and ``pkg::action::Fibonacci`` -> ``pkg/action/Fibonacci``."""
    t = canon_type(name, "action")
    if t is None or t.count("/") != 2:
        return None
    pkg, mid, last = t.split("/")
    if mid in ("msg", "action") and last.endswith("Action") and len(last) > 6:
        last, mid = last[:-6], "action"
    return f"{pkg}/{mid}/{last}" if mid == "action" else None


def service_type(name: str | None) -> str | None:
    """``pkg::Srv``, ``pkg::srv::Srv``, ``pkg::Srv::Request`` -> ``pkg/srv/Srv``."""
    if not name:
        return None
    n = re.sub(r"(::|/|\.)(Request|Response)(::\w+)?$", "", name.strip())
    t = canon_type(n, "srv")
    return t if t and t.count("/") == 2 else None


def _scope_of(n: Any) -> str | None:
    """The qualified class a node lies in: an enclosing class body, or a member
    function defined out of line (``ns::C::f``), under its namespaces."""
    cls: list[str] = []
    nss: list[str] = []
    p = n.parent
    while p is not None:
        if p.type in ("class_specifier", "struct_specifier") and p.child_by_field_name("body") is not None:
            cls.insert(0, treesitter.text(p.child_by_field_name("name")))
        elif p.type == "function_definition" and not cls:
            d = p.child_by_field_name("declarator")
            while d is not None and d.type not in ("function_declarator",):
                d = d.child_by_field_name("declarator")
            q = d.child_by_field_name("declarator") if d is not None else None
            if q is not None and q.type == "qualified_identifier":
                scope = treesitter.text(q.child_by_field_name("scope"))
                if scope:
                    cls.insert(0, scope)
        elif p.type == "namespace_definition" and p.child_by_field_name("name") is not None:
            nss.insert(0, treesitter.text(p.child_by_field_name("name")))
        p = p.parent
    if not cls:
        return None
    return "::".join(x for x in nss + cls if x)


def _tmpl(ty: Any) -> Any:
    """The ``template_type`` inside ``ns::T<A>`` (a qualified identifier), or ``None``."""
    while ty is not None and ty.type == "qualified_identifier":
        ty = ty.child_by_field_name("name")
    return ty if ty is not None and ty.type == "template_type" else None


def _targ(t: Any, aliases: dict[str, str]) -> str | None:
    """The first template argument's text, following ``using``/``typedef`` aliases."""
    if t is None or not t.named_children:
        return None
    s = treesitter.text(t.named_children[0])
    for _ in range(4):
        s2 = aliases.get(s) or aliases.get(s.split("::")[-1])
        if s2 is None or s2 == s:
            break
        s = s2
    return s


def scan_cpp(data: bytes, shown: str) -> dict[str, Any]:
    """``{"nodes": [(name, Src)], "endpoints": [Endpoint], "notes": [Note],
    "classes": {qualified class: {"nodes": [...], "endpoints": [...]}},
    "components": [(qualified class, Src)]}`` for one file.

    tree-sitter recovers from syntax errors, so a broken file still yields
    what it can; its ERROR regions are reported as one located warning."""
    out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": [], "classes": {}, "components": []}
    data = blank_macros(data)

    def src(n: Any) -> Src:
        return Src(shown, n.start_point[0] + 1, n.start_point[1] + 1)

    for m in _REGISTER.finditer(data):
        line = data.count(b"\n", 0, m.start()) + 1
        out["components"].append((m.group(1).decode().lstrip(":"), Src(shown, line, 1)))
    # the registration macro has no semicolon: blanked so that it is not read as a syntax error
    data = _REGISTER.sub(lambda m: b" " * len(m.group(0)), data)
    root = treesitter.parser("cpp").parse(data).root_node
    callbacks: dict[str, str] = {}  # function name -> raw type text of its first parameter
    aliases: dict[str, str] = {}
    fields: dict[str, tuple[str, str]] = {}  # member/variable -> (actionlib role, type text)
    handles: dict[str, str] = {}  # NodeHandle variable -> its namespace ("~" private)
    all_nodes = list(_walk(root))
    for n in all_nodes:
        t = n.type
        if t == "function_declarator":
            name = treesitter.text(n.child_by_field_name("declarator")).split("::")[-1]
            params = n.child_by_field_name("parameters")
            first = next((c for c in (params.children if params else []) if c.type == "parameter_declaration"), None)
            if first is not None and first.child_by_field_name("type") is not None:
                callbacks[name] = treesitter.text(first.child_by_field_name("type"))
        elif t == "alias_declaration":
            ty = n.child_by_field_name("type")
            aliases[treesitter.text(n.child_by_field_name("name"))] = treesitter.text(ty)
        elif t == "type_definition":
            ty = n.child_by_field_name("type")
            for d in n.children_by_field_name("declarator"):
                aliases[treesitter.text(d)] = treesitter.text(ty)
        elif t in ("field_declaration", "declaration", "parameter_declaration"):
            ty = n.child_by_field_name("type")
            tt = treesitter.text(ty)
            base = tt.split("<")[0].split("::")[-1].strip()
            for d in n.children_by_field_name("declarator"):
                var = d.child_by_field_name("declarator") if d.type == "init_declarator" else d
                vname = treesitter.text(var).lstrip("*&").strip()
                if base in _ACTIONLIB and _tmpl(ty) is not None:
                    fields[vname] = (_ACTIONLIB[base], _targ(_tmpl(ty).child_by_field_name("arguments"), aliases) or "")
                    if d.type == "init_declarator":
                        v = d.child_by_field_name("value")
                        if v is not None and v.type in ("argument_list", "initializer_list"):
                            _actionlib(n, list(v.named_children), fields[vname], out, src, aliases, handles, None)
                elif base == "NodeHandle":
                    handles.setdefault(vname, "")
                    v = d.child_by_field_name("value") if d.type == "init_declarator" else None
                    if v is not None and v.named_children and string_value(v.named_children[0]) is not None:
                        handles[vname] = string_value(v.named_children[0]) or ""
    for n in all_nodes:  # NodeHandle members given a namespace in a constructor: pnh_("~")
        if n.type == "field_initializer" and n.named_children and treesitter.text(n.named_children[0]) in handles:
            a = next((c for c in n.children if c.type in ("argument_list", "initializer_list")), None)
            if a is not None and a.named_children and string_value(a.named_children[0]) is not None:
                handles[treesitter.text(n.named_children[0])] = string_value(a.named_children[0]) or ""
    binds = Bindings(all_nodes, handles)
    if root.has_error:
        err = next((n for n in all_nodes if n.type == "ERROR" or n.is_missing), root)
        out["notes"].append(Note(src(err), "C++ source has syntax errors; read what tree-sitter recovered",
                                 "ROS-PARSE"))

    def add_node(name: str, n: Any) -> None:
        out["nodes"].append((name, src(n)))
        cls = _scope_of(n)
        if cls:
            out["classes"].setdefault(cls, {"nodes": [], "endpoints": []})["nodes"].append((name, src(n)))

    for n in all_nodes:
        if n.type == "field_initializer":
            head = n.named_children[0] if n.named_children else None
            args = next((c for c in n.children if c.type in ("argument_list", "initializer_list")), None)
            if head is None or args is None:
                continue
            h = treesitter.text(head)
            if h in _NODE_TYPES:
                s = string_value(args.named_children[0]) if args.named_children else None
                if s is not None:
                    add_node(s, n)
            elif h in fields:
                _actionlib(n, list(args.named_children), fields[h], out, src, aliases, handles, binds)
            continue
        if n.type == "new_expression":
            ty = n.child_by_field_name("type")
            base = treesitter.text(ty).split("<")[0].split("::")[-1].strip()
            a = n.child_by_field_name("arguments")
            if base in _ACTIONLIB and _tmpl(ty) is not None and a is not None:
                role = (_ACTIONLIB[base], _targ(_tmpl(ty).child_by_field_name("arguments"), aliases) or "")
                _actionlib(n, list(a.named_children), role, out, src, aliases, handles, binds)
            continue
        if n.type != "call_expression":
            continue
        fn = n.child_by_field_name("function")
        args_n = n.child_by_field_name("arguments")
        args = list(args_n.named_children) if args_n is not None else []
        if fn is None:
            continue
        name, targs = None, None
        f = fn.child_by_field_name("field") if fn.type == "field_expression" else fn
        if f is not None and f.type == "qualified_identifier" and f.child_by_field_name("name") is not None \
                and f.child_by_field_name("name").type in ("template_function", "template_method"):
            f = f.child_by_field_name("name")
        if f is not None and f.type in ("template_method", "template_function"):
            name = treesitter.text(f.child_by_field_name("name"))
            targs = f.child_by_field_name("arguments")
        elif f is not None:
            name = treesitter.text(f)
        name_last = (name or "").split("::")[-1]
        full = treesitter.text(fn)
        if full == "ros::init" and len(args) >= 3:
            s = string_value(args[2])
            if s is not None:
                add_node(s, n)
            else:
                out["notes"].append(Note(src(args[2]), "node name is not a string literal: not resolved statically"))
            continue
        if name_last == "make_shared" and args:
            tt = treesitter.text(targs)
            if targs is not None and any(x in tt for x in _ACTIONLIB) and targs.named_children:
                inner = targs.named_children[0]
                ty = inner.child_by_field_name("type") if inner.type == "type_descriptor" else inner
                base = treesitter.text(ty).split("<")[0].split("::")[-1].strip()
                if base in _ACTIONLIB and _tmpl(ty) is not None:
                    role = (_ACTIONLIB[base], _targ(_tmpl(ty).child_by_field_name("arguments"), aliases) or "")
                    _actionlib(n, args, role, out, src, aliases, handles, binds)
                continue
            if (targs is not None and tt.strip("<> ") in _NODE_TYPES) or full.endswith("Node::make_shared"):
                s = string_value(args[0])
                if s is not None:
                    add_node(s, n)
                continue
        kind = _CALLS.get(name_last)
        if kind is None or not args:
            continue
        is_action = name_last in ("create_server", "create_client") and "rclcpp_action" in full
        if name_last == "create_server" and not is_action:
            continue
        if is_action:
            kind = "action_servers" if name_last == "create_server" else "action_clients"
            if len(args) < 2:
                continue
            name_arg = args[1]
        else:
            name_arg = args[0]
        ta = _targ(targs, aliases)
        if kind in ("pub", "sub"):
            msg_type = canon_type(ta) if ta else None
            if msg_type is None and kind == "sub" and name_last == "subscribe" and len(args) >= 3:
                cb = treesitter.text(args[2]).lstrip("&").split("::")[-1]
                c = canon_type(callbacks.get(cb))
                msg_type = c if c and c.count("/") == 2 else None
        elif kind.startswith("service"):
            msg_type = service_type(ta)
            if msg_type is None and name_last == "advertiseService" and len(args) >= 2:
                cb = treesitter.text(args[1]).lstrip("&").split("::")[-1]
                msg_type = service_type(callbacks.get(cb))
        else:
            msg_type = action_type(ta)
        recv = fn.child_by_field_name("argument") if fn.type == "field_expression" else None
        _emit(kind, name_arg, msg_type, n, out, src, binds, handles.get(_recv(recv), "") if recv is not None else "")
    return out


def _recv(n: Any) -> str:
    return treesitter.text(n).replace("this->", "").lstrip("*&").strip()


def _actionlib(n: Any, args: list[Any], role: tuple[str, str], out: dict[str, Any], src: Any,
               aliases: dict[str, str], handles: dict[str, str], binds: Bindings | None) -> None:
    """An actionlib server/client constructed with ``args``: the name is the first
    argument, or the second when the first is a NodeHandle."""
    kind, ty = role
    if not args:
        return
    first = _recv(args[0])
    ns = ""
    if len(args) >= 2 and (first in handles or "NodeHandle" in treesitter.text(args[0])):
        ns = handles.get(first, "")
        name_arg = args[1]
    else:
        name_arg = args[0]
    for _ in range(4):
        if ty in aliases:
            ty = aliases[ty]
    _emit(kind, name_arg, action_type(ty), n, out, src, binds, ns)


def _emit(kind: str, name_arg: Any, msg_type: str | None, n: Any, out: dict[str, Any], src: Any,
          binds: Bindings | None, handle_ns: str) -> None:
    what = _WHAT[kind]
    topic, param = string_value(name_arg), None
    if topic is None and binds is not None:
        topic, param = binds.lookup(name_arg)
    if topic is None and param is None:
        out["notes"].append(Note(src(name_arg), f"{what} name is '{treesitter.text(name_arg)[:80]}', not a string literal: "
                                                f"not resolved statically"))
        return
    if topic and handle_ns and not topic.startswith("/"):
        topic = f"~{topic}" if handle_ns == "~" else f"{handle_ns.rstrip('/')}/{topic}"
    if msg_type is None:
        out["notes"].append(Note(src(n), f"type of {what} '{topic or param}' not resolved statically"))
    ep = Endpoint(kind, topic or "", msg_type, src(n), param)
    out["endpoints"].append(ep)
    cls = _scope_of(n)
    if cls:
        out["classes"].setdefault(cls, {"nodes": [], "endpoints": []})["endpoints"].append(ep)
