"""Names that C++ node code keeps in variables and members: string literals
and parameters (docs/ros.md, "Reading real code").

* roscpp: ``h.param("n", var, default)``, ``h.param<T>("n", var, default)``,
  ``var = h.param("n", default)``, ``h.getParam("n", var)``,
  ``ros::param::get("n", var)`` / ``ros::param::param("n", var, default)``;
  the parameter's name is resolved against the handle's namespace
  (``ros::NodeHandle pnh("~")`` makes ``"n"`` the private ``~n``);
* rclcpp: ``declare_parameter("n", default)`` / ``declare_parameter<T>(...)``,
  ``get_parameter("n").as_string()``, ``get_parameter("n", var)``,
  ``get_parameter_or("n", var, default)``; ROS 2 parameters belong to their
  node, so each is the private ``~n``, its default the declared one;
* ``std::string var = "x"`` / ``var = "x"`` / ``std::string("x")``: a literal.

A variable is matched by its name (``this->`` dropped), file-wide; one bound
to two different values is not resolved (said so by the caller).
Source of the name rules: ROS 1 wiki "Names" and "Parameter Server"; ROS 2
design "Parameters".
"""
from __future__ import annotations

from typing import Any

from . import treesitter

_ROS1 = {"param", "getParam", "getParamCached"}
_ROS2 = {"declare_parameter", "get_parameter", "get_parameter_or"}


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


def _key(n: Any) -> str:
    return treesitter.text(n).replace("this->", "").lstrip("*&").strip()


class Bindings:
    """Variable -> (default or literal, parameter) over one file's syntax tree."""

    def __init__(self, nodes: list[Any], handles: dict[str, str]) -> None:
        self._b: dict[str, set[tuple[str | None, str | None]]] = {}
        self._declared: dict[str, str | None] = {}
        self._handles = handles
        for n in nodes:
            if n.type == "call_expression":
                self._call(n)
            elif n.type == "init_declarator":
                v = string_value(n.child_by_field_name("value"))
                if v is None and n.child_by_field_name("value") is not None \
                        and n.child_by_field_name("value").type == "initializer_list":
                    ch = n.child_by_field_name("value").named_children
                    v = string_value(ch[0]) if len(ch) == 1 else None
                if v is not None:
                    self._bind(n.child_by_field_name("declarator"), v, None)
            elif n.type == "assignment_expression":
                v = string_value(n.child_by_field_name("right"))
                if v is not None:
                    self._bind(n.child_by_field_name("left"), v, None)

    def _bind(self, var: Any, default: str | None, param: str | None) -> None:
        if var is not None:
            self._b.setdefault(_key(var), set()).add((default, param))

    def getter(self, n: Any) -> tuple[str, str | None, Any] | None:
        """``(parameter, default, by-reference variable node or None)`` when call ``n``
        reads a parameter, else ``None``."""
        fn = n.child_by_field_name("function")
        a = n.child_by_field_name("arguments")
        args = list(a.named_children) if a is not None else []
        if fn is None or not args:
            return None
        f = fn.child_by_field_name("field") if fn.type == "field_expression" else fn
        if f is not None and f.type in ("template_method", "template_function"):
            f = f.child_by_field_name("name")
        last = treesitter.text(f).split("::")[-1]
        pname = string_value(args[0])
        if pname is None:
            return None
        full = treesitter.text(fn)
        if last in _ROS1 and (fn.type == "field_expression" or full.startswith("ros::param::")):
            if full.startswith("ros::param::") and last not in ("get", "param"):
                return None
            ns = self._handles.get(_key(fn.child_by_field_name("argument")), "") \
                if fn.type == "field_expression" else ""
            if not pname.startswith(("/", "~")) and ns:
                pname = f"~{pname}" if ns == "~" else f"{ns.rstrip('/')}/{pname}"
            if last == "getParam" or last == "getParamCached":
                return (pname, None, args[1]) if len(args) >= 2 else None
            if len(args) == 3:
                return pname, string_value(args[2]), args[1]
            if len(args) == 2:
                return pname, string_value(args[1]), None
            return None
        if full.startswith("ros::param::") and last in ("get", "param"):
            if last == "get":
                return (pname, None, args[1]) if len(args) >= 2 else None
            return (pname, string_value(args[2]), args[1]) if len(args) == 3 else None
        if last in _ROS2:
            p = pname if pname.startswith("~") else f"~{pname}"
            if last == "declare_parameter":
                d = string_value(args[1]) if len(args) >= 2 else None
                self._declared.setdefault(p, d)
                return p, d, None
            if last == "get_parameter":
                return (p, None, args[1]) if len(args) >= 2 else (p, None, None)
            return (p, string_value(args[2]) if len(args) >= 3 else None, args[1]) if len(args) >= 2 else None
        return None

    def _call(self, n: Any) -> None:
        g = self.getter(n)
        if g is None:
            return
        param, default, ref = g
        if ref is not None:
            self._bind(ref, default, param)
            return
        p = n.parent
        while p is not None and p.type in ("field_expression", "call_expression", "argument_list",
                                           "template_method", "parenthesized_expression"):
            if p.type == "argument_list":
                return  # passed on to another call: read where it is used (inline)
            p = p.parent
        if p is not None and p.type == "assignment_expression":
            self._bind(p.child_by_field_name("left"), default, param)
        elif p is not None and p.type == "init_declarator":
            self._bind(p.child_by_field_name("declarator"), default, param)

    def lookup(self, n: Any) -> tuple[str | None, str | None]:
        """``(default or literal, parameter)`` for a name argument ``n`` (a variable, a
        member, an inline parameter read); ``(None, None)`` when not resolved."""
        if n.type == "call_expression":
            for c in _calls(n):
                g = self.getter(c)
                if g is not None:
                    return self._with_default(g[1], g[0])
            return None, None
        vals = self._b.get(_key(n))
        if not vals or len(vals) != 1:
            return None, None
        d, p = next(iter(vals))
        return self._with_default(d, p) if p else (d, None)

    def _with_default(self, default: str | None, param: str) -> tuple[str | None, str | None]:
        if default is None:
            default = self._declared.get(param)
        return default, param


def _calls(n: Any):  # type: ignore[no-untyped-def]
    """A call and the calls on its result (``get_parameter("t").as_string()``), never
    calls in its arguments (``f(get_parameter("t"))`` is not the parameter)."""
    x = n
    while x is not None and x.type in ("call_expression", "field_expression"):
        if x.type == "call_expression":
            yield x
            x = x.child_by_field_name("function")
        else:
            x = x.child_by_field_name("argument")
