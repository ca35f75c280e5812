"""The constructions of a C++ node source: what a declaration, a ``new``, a
``make_shared`` or a constructor's member initialiser makes (the list of
recognised forms is :mod:`.sources_cpp`'s docstring): a node (``rclcpp::Node``,
``LifecycleNode``, a workspace base class), an actionlib server or client, a
helper's endpoints (:mod:`cpp_helpers`), a helper that makes its own node, or
a construction of the program's own classes, recorded for the linker
(:mod:`link`).  Mixed into :class:`~.sources_cpp._File`, which gives ``out``
(the file's record), ``scope`` (:mod:`cpp_values`), ``aliases``, ``ros2``,
``vex_at``, ``src``, ``emit``, ``node``, ``record`` and ``specs``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import cpp_helpers, treesitter
from rclverify.ros.extract.cpp_bases import node_base
from rclverify.ros.extract.cpp_calls import LIBRARY
from rclverify.ros.extract.cpp_names import base_name
from rclverify.ros.extract.cpp_types import action_type_in, split_template
from rclverify.ros.extract.model import Note

_ACTIONLIB = {"SimpleActionServer": "action_servers", "ActionServer": "action_servers",
              "SimpleActionClient": "action_clients", "ActionClient": "action_clients"}
_NODE_TYPES = {"Node", "LifecycleNode"}
_T = treesitter.text


class ConstructionReader:
    """The construction-reading part of :class:`~.sources_cpp._File` (module docstring)."""

    if TYPE_CHECKING:  # the file reader's state and helpers the mixin reads, declared for the type checker only
        def __getattr__(self, name: str) -> Any: ...

    # -- constructions
    def construct(self, type_text: str, args: list[Any], at: Any) -> None:
        head, targs = split_template(type_text.replace("typename", "").strip())
        base = head.split("::")[-1]
        if base in _NODE_TYPES and ("rclcpp" in head or head == base) and args:
            self.node(self.scope.value(args[0]), at, self.scope.value(args[1]) if len(args) > 1 else None,
                      "lifecycle" if base == "LifecycleNode" else None, args)
            return
        if base in _ACTIONLIB and targs and "actionlib" in head + type_text:
            self.actionlib(_ACTIONLIB[base], targs[0], args, at)
            return
        if cpp_helpers.own_node(type_text, args, self.ros2):
            self.own_node(at)
            return
        specs = cpp_helpers.constructed(type_text, args, self.scope.value, self.ros2, self.aliases)
        if specs is not None:
            self.specs(specs, at)
            return
        if head and not head.startswith(LIBRARY):  # with its template arguments (a template's types)
            self.record("ctor", type_text.replace("typename", "").strip() if targs else head, args, at)

    def own_node(self, at: Any) -> None:
        self.out["notes"].append(Note(self.src(at), cpp_helpers.OWN_NODE_SAID, "ROS-TF-OWN-NODE"))

    def actionlib(self, kind: str, ty: str, args: list[Any], at: Any) -> None:
        if not args:
            return
        first_handle = len(args) >= 2 and self.scope.is_handle(args[0])
        name_arg = args[1] if first_handle else args[0]
        h = self.scope.value(args[0]) if first_handle else None
        self.emit(kind, name_arg, action_type_in(self.aliases.get(ty, ty), self.scope.using_ns), at, h)

    def initializer(self, n: Any) -> None:
        head = n.named_children[0] if n.named_children else None
        args = next((c for c in n.children if c.type in ("argument_list", "initializer_list")), None)
        if head is None or args is None:
            return
        h = _T(head)
        kind = node_base(h, self.ros2)
        if kind is not None and args.named_children:
            a = args.named_children
            self.node(self.scope.value(a[0]), n, self.scope.value(a[1]) if len(a) > 1 and
                      self.scope.value(a[1]) is not None and self.scope.value(a[1])[0] == "str" else None,
                      "lifecycle" if kind == "lifecycle" else None, list(a))
            if "::" in h and "rclcpp" not in h:  # a workspace base (pkg_util::LifecycleNode): the linker runs it too
                self.record("member", h, list(args.named_children), n)
            return
        ty = self.scope.type_of(head)  # a member tf_(buffer_) declared tf2_ros::TransformListener tf_;
        if ty is not None and cpp_helpers.own_node(self.aliases.get(ty, ty), list(args.named_children), self.ros2):
            self.own_node(n)
            self.record("own-node", h, [], n)  # initialised here: the linker makes no default one
            return
        self.record("member", h, list(args.named_children), n)

    def declaration(self, n: Any) -> None:
        ty = _T(n.child_by_field_name("type"))
        base = base_name(ty)
        if not ty or base in ("auto", "NodeHandle") or n.child_by_field_name("type").type == "primitive_type":
            return
        for d in n.children_by_field_name("declarator"):
            if d.type == "init_declarator":
                v = d.child_by_field_name("value")
                if v is not None and v.type in ("argument_list", "initializer_list"):
                    self.construct(ty, list(v.named_children), n)
            elif d.type == "identifier":
                self.construct(ty, [], n)
            elif d.type == "function_declarator" and self.scope.fn_of(n) is not None:
                self.vexing(ty, d, n)

    def vexing(self, ty: str, d: Any, n: Any) -> None:
        """``Sensor s(nh, name());`` in a function body, which the grammar reads as a
        function declaration (C++'s "most vexing parse"): its parentheses re-read
        as call arguments, evaluated in the enclosing function."""
        params = d.child_by_field_name("parameters")
        if params is None:
            return
        tree = treesitter.parser("cpp").parse(b"void f_(){g_" + params.text + b";}").root_node
        call = next((x for x in treesitter.walk(tree) if x.type == "call_expression"), None)
        a = call.child_by_field_name("arguments") if call is not None else None
        if a is None:
            return
        self.scope.override, self.vex_at = self.scope.fn_of(n), n
        try:
            self.construct(ty, list(a.named_children), n)
        finally:
            self.scope.override, self.vex_at = None, None
