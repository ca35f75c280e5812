"""Message, service and action types as C++ code writes them, read into the
graph's canonical names (``pkg/msg/T``, ``pkg/srv/T``, ``pkg/action/T``;
docs/ros.md, "Reading real code").

A type's text (a template argument, a callback's parameter type) is read
through:

* ``using``/``typedef`` aliases of the file (followed four deep), looked up
  in the scope of the use (:func:`alias_of`): a name qualified by a
  namespace is never another class's alias of its last part;
* qualifiers and pointers: ``const``, ``&``, ``*``, ``typename``;
* wrappers: ``std::shared_ptr<T>``, ``boost::shared_ptr<const T>``,
  ``std::unique_ptr<T>``, ``ros::MessageEvent<T const>``;
* the generated pointer names: ``T::ConstPtr``, ``T::SharedPtr``,
  ``T::ConstSharedPtr``, ``T::UniquePtr`` and ROS 1's glued ``pkg::TConstPtr``
  / ``pkg::TPtr`` (roscpp's generated typedefs);
* ``rclcpp::TypeAdapter<Custom, pkg::msg::T>`` and
  ``rclcpp::adapt_type<Custom>::as<pkg::msg::T>``: the ROS type, the second
  argument (rclcpp's type adaptation, REP 2007).

* ``RCLCPP_USING_CUSTOM_TYPE_AS_ROS_MESSAGE_TYPE(Custom, pkg::msg::T)``
  (:func:`adapted`): ``Custom`` is then ``pkg::msg::T`` wherever the program
  writes it (``create_publisher<Custom>``); a type of a namespace that holds
  no messages (``cv::Mat``, ``std::string``) is never read as one.

Sources: roscpp's message generator (``genpy``/``gencpp`` typedefs), rclcpp
``type_adapter.hpp``.
"""
from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

from rclverify.ros.extract.model import canon_type

_WRAPPERS = {"shared_ptr", "unique_ptr", "weak_ptr", "MessageEvent", "ConstSharedPtr"}
_QUALS = re.compile(r"\b(?:const|volatile|typename|struct|class)\b|[&*]")


def split_template(text: str) -> tuple[str, list[str]]:
    """``"a::B<C, D<E>>::F"`` -> ``("a::B", ["C", "D<E>"])``: the name before the first
    ``<`` and the top-level arguments of that bracket (``[]`` without one)."""
    i = text.find("<")
    if i < 0:
        return text.strip(), []
    depth, start, args = 0, i + 1, []
    for j in range(i, len(text)):
        c = text[j]
        if c == "<":
            depth += 1
        elif c == ">":
            depth -= 1
            if depth == 0:
                args.append(text[start:j].strip())
                break
        elif c == "," and depth == 1:
            args.append(text[start:j].strip())
            start = j + 1
    return text[:i].strip(), [a for a in args if a]


def _after(text: str) -> str:
    """What follows the first top-level template bracket: ``"X<A>::B"`` -> ``"::B"``."""
    depth = 0
    for j, c in enumerate(text):
        if c == "<":
            depth += 1
        elif c == ">":
            depth -= 1
            if depth == 0:
                return text[j + 1:]
    return ""


def _namespace_like(qualifier: str) -> bool:
    """Whether ``qualifier`` (what precedes a name's last ``::``) names a
    namespace rather than a class: its last part is lower-case (ROS packages
    and the ``msg``/``srv``/``action`` namespaces of generated interfaces are,
    by REP 144 and the ROS 2 C++ style; classes are CamelCase)."""
    last = qualifier.split("::")[-1].split("<")[0]
    return not last or last[0].islower() or last[0] == "_"


def alias_index(aliases: Mapping[str, str]) -> dict[str, list[str]]:
    """The keys of ``aliases`` by their last ``::`` part, for :func:`alias_of`."""
    out: dict[str, list[str]] = {}
    for k in aliases:
        out.setdefault(k.rsplit("::", 1)[-1], []).append(k)
    return out


def alias_of(text: str, aliases: Mapping[str, str], scopes: Sequence[str] = (),
             index: Mapping[str, list[str]] | None = None) -> str | None:
    """What the ``using``/``typedef`` alias written ``text`` stands for, looked up
    as C++ does (ISO C++ [basic.lookup]): a bare name in ``scopes`` (qualified
    class or namespace names, innermost first) and then among the aliases
    whose bare name is unique in the program; a qualified name by its
    qualification (``ns::Cls::Alias``, or a unique key ending so); a name
    qualified by a namespace (``other_msgs::srv::Charge``) is never another
    class's alias of its last part.  ``aliases`` holds bare names and
    scope-qualified ones (:mod:`sources_cpp`); ``index`` (:func:`alias_index`
    of ``aliases``) spares a walk over every key.  ``None``: no alias."""
    if "::" not in text:
        for sc in scopes:
            hit = aliases.get(f"{sc}::{text}")
            if hit is not None:
                return hit
        return aliases.get(text)
    hit = aliases.get(text)
    if hit is not None:
        return hit
    qual, last = text.rsplit("::", 1)
    if qual.rsplit("::", 1)[-1] in ("msg", "srv", "action"):
        return None  # a generated interface's name (pkg::msg::T), never an alias
    keys = index.get(last, ()) if index is not None else aliases
    ends = {aliases[k] for k in keys if k.endswith("::" + text)}
    if len(ends) == 1:
        return next(iter(ends))
    return None if _namespace_like(qual) or ends else aliases.get(last)


def plain(text: str | None, aliases: dict[str, str] | None = None) -> str | None:
    """The C++ type ``text`` as the ROS type's qualified name (``pkg::msg::T``), or
    ``None`` when empty: aliases followed, qualifiers, pointer wrappers and
    generated pointer names dropped, a type adapter read as its ROS type."""
    if not text:
        return None
    aliases = aliases or {}
    s = " ".join(_QUALS.sub(" ", text).split())
    for _ in range(8):
        s = s.replace(" ", "")
        hit = alias_of(s, aliases)
        if hit is not None and hit != s:
            s = " ".join(_QUALS.sub(" ", hit).split()).replace(" ", "")
            continue
        head, args = split_template(s)
        last = head.split("::")[-1]
        if last == "TypeAdapter" and len(args) == 2:
            s = args[1]
            continue
        if last == "adapt_type" and args:
            m = re.search(r"::as<(.+)>$", s)
            if m:
                s = m.group(1)
                continue
        if last in _WRAPPERS and args:
            s = args[0]
            continue
        if args and _after(s).startswith("::"):  # rclcpp::Subscription<T>::SharedPtr: not a message
            return None
        break
    for suffix in ("::ConstSharedPtr", "::SharedPtr", "::ConstPtr", "::UniquePtr", "::WeakPtr", "::Ptr"):
        if s.endswith(suffix):
            s = s[: -len(suffix)]
            break
    else:
        m = re.fullmatch(r"(.+::[A-Z]\w*?)(ConstPtr|Ptr)", s)
        if m:
            s = m.group(1)
    return s or None


def message_type(text: str | None, aliases: dict[str, str] | None = None) -> str | None:
    """``pkg/msg/T`` for a C++ message type's text (see :func:`plain`), or ``None``
    when it does not name a message of a package."""
    p = plain(text, aliases)
    if p is None or "<" in p or "::" not in p or p.split("::")[0] in _NOT_PACKAGES:
        return None  # cv::Mat, std::string: a custom type no adapter names is no message
    t = canon_type(p)
    return t if t and t.count("/") == 2 and t.split("/")[1] == "msg" else None


def action_type(name: str | None) -> str | None:
    """``pkg::FibonacciAction`` / ``pkg/msg/FibonacciAction`` (ROS 1 actionlib's
    generated message) and ``pkg::action::Fibonacci`` -> ``pkg/action/Fibonacci``."""
    t = canon_type(plain(name) if name and "::" in name else name, "action")
    if t is None or t.count("/") != 2:
        return None
    pkg, mid, last = t.split("/")
    if mid in ("msg", "action") and last.endswith("Action") and len(last) > 6:
        last, mid = last[:-6], "action"
    return f"{pkg}/{mid}/{last}" if mid == "action" else None


_NOT_PACKAGES = ("std", "ros", "boost", "actionlib", "Eigen", "rclcpp", "cv", "tf", "tf2", "tf2_ros")


def action_type_in(name: str | None, using_ns: list[str]) -> str | None:
    """:func:`action_type`, and for a bare ``XAction`` under one ``using namespace
    pkg;`` of a package (not ``std``, ``ros``, ``boost`` ...), ``pkg/action/X``."""
    t = action_type(name)
    if t is not None or not name or "::" in name or not name.strip().endswith("Action"):
        return t
    pkgs = sorted({ns.strip(":") for ns in using_ns if ns and ns.strip(":").split("::")[0] not in _NOT_PACKAGES})
    return action_type(f"{pkgs[0]}::{name.strip()}") if len(pkgs) == 1 else None


def service_type(name: str | None) -> str | None:
    """``pkg::Srv``, ``pkg::srv::Srv``, ``pkg::Srv::Request`` (also as a
    ``SharedPtr`` or reference) -> ``pkg/srv/Srv``."""
    if not name:
        return None
    n = plain(name) if "::" in name else name.strip()
    if n is None:
        return None
    n = re.sub(r"(::|/|\.)(Request|Response)(::\w+)?$", "", n)
    n = re.sub(r"_(Request|Response)$", "", n)
    t = canon_type(n, "srv")
    return t if t and t.count("/") == 2 else None


def callback_name(text: str) -> str:
    """The function a callback argument names: ``&Listener::callback`` ->
    ``Listener::callback``; ``boost::bind(&C::f, this, _1)`` -> ``C::f``."""
    t = text.strip()
    if "(" in t and "&" in t:  # a bind expression: its first argument
        t = t[t.index("(") + 1:].split(",")[0]
    return t.strip().lstrip("&").strip()


_ADAPTED = re.compile(rb"RCLCPP_USING_CUSTOM_TYPE_AS_ROS_MESSAGE_TYPE\s*\(\s*([\w:]+)\s*,\s*([\w:]+)\s*\)")


def adapted(data: bytes) -> dict[str, str]:
    """``{custom type: "rclcpp::TypeAdapter<custom, ros type>"}`` for each
    ``RCLCPP_USING_CUSTOM_TYPE_AS_ROS_MESSAGE_TYPE(custom, ros type)`` of a file's
    bytes (rclcpp ``type_adapter.hpp``: the macro makes ``custom`` an implicit
    type adapter of the ROS type), read before the macro is blanked as an
    upper-case statement (:mod:`cpp_prep`)."""
    out: dict[str, str] = {}
    for m in _ADAPTED.finditer(data):
        c, r = m.group(1).decode(), m.group(2).decode()
        out[c.lstrip(":")] = f"rclcpp::TypeAdapter<{c},{r}>"
    return out
