"""What a C++ class holds that the linker makes endpoints of (docs/ros.md,
"Reading real code"): helper objects held by value as members, helper
classes a class derives from, and helper methods called on a member whose
class another file declares.  Mixed into :class:`~.sources_cpp._File`,
which gives ``out`` (the file's record), ``scope`` (:mod:`cpp_values`) and
``src``.

* ``member_decls``: ``(class, member, type, where)`` of a value member whose
  type is a helper (``tf2_ros::TransformBroadcaster br_;``,
  ``diagnostic_updater::Updater updater_;``, an actionlib server): made with
  the class, by its constructor's initialiser or by default;
* ``base_decls``: ``(class, base, where)`` of a base class that is a helper
  (``class Diagnostics : private diagnostic_updater::Updater``): made with
  every object of the class, by the constructor's initialiser of the base
  or by default; located at the base clause;
* ``member_calls``: a helper method (``it_.advertise("image", 1)``) on a member
  of a class this file does not declare, read by the linker.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import cpp_helpers, treesitter
from rclverify.ros.extract.cpp_names import namespaces_of
from rclverify.ros.extract.cpp_types import split_template
from rclverify.ros.extract.model import Src
from rclverify.ros.extract.cpp_params import string_value

_ACTIONLIB = {"SimpleActionServer", "ActionServer", "SimpleActionClient", "ActionClient"}
_T = treesitter.text


def held_helper(type_text: str) -> bool:
    """Whether a member or base of type ``type_text`` may be a helper object
    (its last name part is a helper's or an actionlib class's)."""
    head, _targs = split_template(type_text.replace(" ", ""))
    last = head.split("::")[-1]
    return last in _ACTIONLIB or last in cpp_helpers.CONSTRUCTED


class MemberReader:
    """The member-related part of the C++ file reader (see the module docstring)."""

    out: dict[str, Any]
    scope: Any

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def src(self, n: Any) -> Src:
            ...

    def member(self, n: Any) -> None:
        """A field declaration ``n`` of a class body: a helper held by value is recorded."""
        ty = _T(n.child_by_field_name("type"))
        ty = getattr(self, "aliases", {}).get(ty.strip(), ty)  # typedef dynamic_reconfigure::Server<C> Srv;
        if self.scope.fn_of(n) is not None or not held_helper(ty):
            return
        nss, cls = namespaces_of(n)
        init = n.child_by_field_name("default_value")
        if init is not None and init.type in ("initializer_list", "argument_list") and init.named_children:
            # a default member initializer (Sub<T> sub_{this, "~/input/x"}): made with every object of the class
            getattr(self, "construct")(ty, list(init.named_children), n)
            return
        for d in n.children_by_field_name("declarator"):
            if d.type == "field_identifier":  # a value member (a pointer is made elsewhere)
                self.out["member_decls"].append(("::".join(nss + cls), _T(d), ty, self.src(n)))

    def bases(self, n: Any) -> None:
        """A class body ``n`` deriving from helpers: each such base is recorded."""
        name = n.child_by_field_name("name")
        if name is None or n.child_by_field_name("body") is None:
            return
        nss, cls = namespaces_of(n)
        unit = "::".join(nss + cls + [_T(name).split("<")[0]])
        for c in n.children:
            if c.type != "base_class_clause":
                continue
            for b in c.named_children:
                if b.type != "access_specifier" and held_helper(_T(b)):
                    self.out.setdefault("base_decls", []).append((unit, _T(b), self.src(b)))

    def deferred_method(self, recv: Any, method: str, args: list[Any], at: Any) -> bool:
        """A helper method on a member whose class this file does not declare
        (``it_.advertise("image", 1)``, ``sub_.subscribe(nh, "t", 1)``): left to
        the linker, which knows the member's type from the program's other files."""
        r = recv.child_by_field_name("field") if recv.type == "field_expression" else recv
        fn = self.scope.fn_of(at)
        if fn is None or not fn.in_class or r is None or r.type not in ("identifier", "field_identifier"):
            return False
        self.out["member_calls"].append((fn.unit, _T(r), method, [self.scope.value(x) for x in args],
                                         [_T(x) for x in args], self.src(at), fn.key))
        return True

    def helper_form(self, method: str, args: list[Any]) -> bool:
        """Whether a call without template arguments has the form of a helper's method
        only (never of a node handle's): ``advertise(name, n)``, the camera forms,
        message_filters' ``subscribe(h, name, ...)``, ``on_parameter_event(cb)``,
        a realtime publisher's ``init(h, name, n)``."""
        if method in ("advertiseCamera", "subscribeCamera", "on_parameter_event"):
            return True
        if method == "init":  # realtime_tools' pub.init(nh, "topic", 1)
            return len(args) >= 2 and string_value(args[1]) is not None
        if method == "advertise":
            return len(args) >= 2
        return method == "subscribe" and len(args) >= 2 and (
            self.scope.is_handle(args[0]) or (string_value(args[0]) is None and string_value(args[1]) is not None))
