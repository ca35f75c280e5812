"""ROS parameter reads in C++ node code, and string literals (docs/ros.md,
"Reading real code").

* roscpp: ``h.param("n", var, default)``, ``h.param<T>("n", var, default)``,
  ``var = h.param("n", default)``, ``h.getParam("n", var)``,
  ``ros::param::get("n", var)`` / ``ros::param::param("n", var, default)``;
  the parameter's name is resolved against the handle's namespace
  (``ros::NodeHandle pnh("~")`` makes ``"n"`` the private ``~n``; the caller
  gives the handle, :mod:`cpp_scope`);
* rclcpp: ``declare_parameter("n", default)`` / ``declare_parameter<T>(...)``,
  ``get_parameter("n").as_string()``, ``get_parameter("n", var)``,
  ``get_parameter_or("n", var, default)``; ROS 2 parameters belong to their
  node, so each is the private ``~n``, its default the declared one (a string,
  or ``rclcpp::ParameterValue("x")``; also through a stack's
  ``declare_parameter_if_not_declared(node, "n", value)``).  A ROS 2 key
  computed in the code (``source_name_ + ".topic"``) is known by its text
  (:func:`key_text`) and read by its value where the program gives it
  (:mod:`cpp_values`, :mod:`link_values`).

Source of the name rules: ROS 1 wiki "Names" and "Parameter Server"; ROS 2
design "Parameters".
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import treesitter

_ROS1 = {"param", "getParam", "getParamCached"}
_ROS2 = {"declare_parameter", "get_parameter", "get_parameter_or"}
_IF_NOT_DECLARED = "declare_parameter_if_not_declared"  # a helper of real stacks: (node, name, value)
KEY = "~{"  # the prefix of a computed ROS 2 parameter key's text: ``~{source_name_+".topic"}``


def key_text(n: Any) -> str:
    """The text a computed parameter key is known by in its file (``~{...}``, blanks
    dropped), the same at its ``declare_parameter`` and its ``get_parameter``."""
    return KEY + "".join(treesitter.text(n).split()) + "}"


def default_value(n: Any) -> str | None:
    """A declared default: a string (:func:`string_value`), also wrapped as
    ``rclcpp::ParameterValue("x")`` (rclcpp's ``ParameterValue`` API)."""
    if n is not None and n.type == "call_expression" and \
            treesitter.text(n.child_by_field_name("function")).split("::")[-1] == "ParameterValue":
        a = n.child_by_field_name("arguments")
        return string_value(a.named_children[0]) if a is not None and len(a.named_children) == 1 else None
    return string_value(n)


def string_value(n: Any) -> str | None:
    """A string literal's value; ``std::string("x")`` / ``std::string{"x"}`` too;
    ``None`` for anything else (an escape sequence too: not guessed)."""
    if n is None:
        return None
    if n.type in ("call_expression", "compound_literal_expression"):
        a = n.child_by_field_name("arguments") or n.child_by_field_name("value")
        fn = n.child_by_field_name("function") or n.child_by_field_name("type")
        if treesitter.text(fn) in ("std::string", "string") and a is not None and len(a.named_children) == 1:
            return string_value(a.named_children[0])
        return None
    if n.type != "string_literal":
        return None
    if any(c.type == "escape_sequence" for c in n.children):
        return None
    parts = [c for c in n.children if c.type == "string_content"]
    return treesitter.text(parts[0]) if parts else ""


def param_read(n: Any) -> tuple[str, str | None, Any, Any, bool] | None:
    """``(parameter, default, by-reference variable node or None, handle node or
    None, ROS 2?)`` when call ``n`` reads a parameter, else ``None``.  A ROS 2
    parameter's name is ``~n``; a ROS 1 one is as written, to be resolved
    against the handle's namespace."""
    if n.type != "call_expression":
        return None
    fn = n.child_by_field_name("function")
    a = n.child_by_field_name("arguments")
    args = list(a.named_children) if a is not None else []
    if fn is None or not args:
        return None
    f = fn.child_by_field_name("field") if fn.type == "field_expression" else fn
    if f is not None and f.type in ("template_method", "template_function"):
        f = f.child_by_field_name("name")
    last = treesitter.text(f).split("::")[-1]
    if last == _IF_NOT_DECLARED and len(args) >= 2:  # pkg_util::declare_parameter_if_not_declared(node, n, v)
        last, args = "declare_parameter", args[1:]
    if last not in _ROS1 and last not in _ROS2 and last not in ("get",):
        return None
    pname = string_value(args[0])
    if pname is None and last in _ROS2:  # a computed key (source_name_ + ".topic"): read by its value
        pname = key_text(args[0])
    if pname is None:
        return None
    full = treesitter.text(fn)
    recv = fn.child_by_field_name("argument") if fn.type == "field_expression" else None
    if last in _ROS1 and (recv is not None or full.startswith("ros::param::")):
        if full.startswith("ros::param::") and last != "param":
            return None
        if last in ("getParam", "getParamCached"):
            return (pname, None, args[1], recv, False) if len(args) >= 2 else None
        if len(args) == 3:
            return pname, string_value(args[2]), args[1], recv, False
        if len(args) == 2:
            return pname, string_value(args[1]), None, recv, False
        return None
    if full.startswith("ros::param::") and last == "get":
        return (pname, None, args[1], None, False) if len(args) >= 2 else None
    if last in _ROS2:
        p = pname if pname.startswith("~") else f"~{pname}"
        if last == "declare_parameter":
            return p, default_value(args[1]) if len(args) >= 2 else None, None, None, True
        if last == "get_parameter":
            return (p, None, args[1], None, True) if len(args) >= 2 else (p, None, None, None, True)
        return (p, string_value(args[2]) if len(args) >= 3 else None, args[1], None, True) if len(args) >= 2 else None
    return None
