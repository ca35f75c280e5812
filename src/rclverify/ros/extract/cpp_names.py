"""The names C++ syntax writes, read from tree-sitter's syntax tree: a
call's callee (its text, last name part and template arguments), a
declarator's name, a function's name without template arguments, the
namespaces and classes around a syntax node, a declared type's base name
and whether it is a node or a node handle.  The scopes that index them are
:mod:`cpp_scope`'s.
"""
from __future__ import annotations

import re

from typing import Any

from rclverify.ros.extract import treesitter

_T = treesitter.text


def callee_parts(fn: Any) -> tuple[str, str, list[str]]:
    """A call's function ``fn`` as ``(its text without template arguments, the last
    part of its name, the template arguments' texts)``."""
    f = fn.child_by_field_name("field") if fn.type == "field_expression" else fn
    if f is not None and f.type == "dependent_name" and f.named_children:  # node->template create_service<T>
        f = f.named_children[-1]
    while f is not None and f.type == "qualified_identifier" and f.child_by_field_name("name") is not None:
        f = f.child_by_field_name("name")
    targs: list[str] = []
    if f is not None and f.type in ("template_method", "template_function"):
        a = f.child_by_field_name("arguments")
        targs = [_T(x) for x in a.named_children] if a is not None else []
        name = _T(f.child_by_field_name("name"))
    else:
        name = _T(f)
    full = _T(fn).replace("template ", "")
    head = full.split("<")[0].strip()
    if "<" in full and ">::" in full:  # rclcpp::Node::make_shared / X<T>::create
        head = head + full[full.rindex(">") + 1:]
    return head, name.split("::")[-1], targs



def is_node_type(type_text: str) -> bool:
    """Whether a declared type is a node handle or a node (``ros::NodeHandle``,
    ``rclcpp::Node::SharedPtr``, ``rclcpp_lifecycle::LifecycleNode *``,
    ``std::shared_ptr<rclcpp::Node>`` ...)."""
    t = type_text.replace(" ", "")
    if "NodeOptions" in t:  # rclcpp::NodeOptions: a node's settings, not a node
        return False
    return "NodeHandle" in t or "rclcpp::Node" in t or "LifecycleNode" in t or t.split("<")[0].endswith("Node")



def untemplated(name: str) -> str:
    """A function's declarator name without template argument lists:
    ``RosFilter<T>::initialize`` -> ``RosFilter::initialize`` (an out-of-line member
    of a class template), ``make<T>`` -> ``make``."""
    for _ in range(8):
        new = re.sub(r"<[^<>()]*>", "", name)
        if new == name:
            break
        name = new
    return name.split("<")[0]



def base_name(type_text: str) -> str:
    """``const ros::NodeHandle &`` -> ``NodeHandle``; ``std::shared_ptr<X>`` -> ``shared_ptr``."""
    return type_text.split("<")[0].replace("&", " ").replace("*", " ").split()[-1].split("::")[-1] \
        if type_text.strip() else ""



def namespaces_of(n: Any) -> tuple[list[str], list[str]]:
    """``(enclosing namespaces, enclosing class names)`` of syntax node ``n``, outermost first."""
    cls: list[str] = []
    nss: list[str] = []
    p = n.parent
    while p is not None:
        if p.type in ("class_specifier", "struct_specifier") and p.child_by_field_name("body") is not None:
            nm = p.child_by_field_name("name")
            if nm is not None:
                cls.insert(0, _T(nm).split("<")[0])
        elif p.type == "namespace_definition" and p.child_by_field_name("name") is not None:
            nss.insert(0, _T(p.child_by_field_name("name")))
        p = p.parent
    return nss, cls



def declarator_name(d: Any) -> Any:
    """The name node a declarator ``d`` declares, through its pointer, reference, initialiser, array,
    function and parenthesised declarators (``None`` when it names none)."""
    while d is not None and d.type in ("pointer_declarator", "reference_declarator", "init_declarator",
                                       "array_declarator", "function_declarator", "parenthesized_declarator"):
        nxt = d.child_by_field_name("declarator")
        if nxt is None:
            nxt = next((c for c in d.named_children if c.type in ("identifier", "field_identifier",
                                                                   "qualified_identifier")), None)
        d = nxt
    return d
