"""The calls of a C++ node source that make endpoints and node names, read
call by call (the list of recognised forms is :mod:`.sources_cpp`'s
docstring).  Mixed into :class:`~.sources_cpp._File`, which gives ``out``
(the file's record), ``scope`` (:mod:`cpp_values`), ``aliases``, ``src``,
``emit``, ``node``, ``construct``, ``record``, ``specs`` and the tests of a
receiver (``helper_form``, ``deferred_method``, ``rclcpp_like``,
``generic_node``).  A call that makes no endpoint here and is the program's
own is recorded for the linker (:mod:`link`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import cpp_helpers, emit, symbols, treesitter
from rclverify.ros.extract.cpp_names import callee_parts
from rclverify.ros.extract.cpp_types import action_type, callback_name, service_type
from rclverify.ros.extract.model import Note, canon_type

#: The endpoint role of each method of a node handle or node, by its name.
_CALLS = {"advertise": "pub", "subscribe": "sub", "create_publisher": "pub", "create_subscription": "sub",
          "advertiseService": "service_servers", "serviceClient": "service_clients",
          "create_service": "service_servers", "create_client": "service_clients",
          "create_generic_publisher": "pub", "create_generic_subscription": "sub"}
#: rclcpp's node methods whose interface type is a template parameter no argument deduces
_TEMPLATED = ("create_publisher", "create_subscription", "create_service", "create_client")
#: component_interface_utils' NodeAdaptor methods, each making its member argument with its Spec
_INIT = {"init_pub": "pub", "init_sub": "sub", "init_srv": "service_servers", "init_cli": "service_clients"}
#: Prefixes of library names: a call of one is no call of the program's own code.
LIBRARY = ("std::", "ros::", "rclcpp::", "boost::", "RCLCPP_", "ROS_", "tf2::", "Eigen::", "rcutils_", "rcl_")
_T = treesitter.text


class CallReader:
    """The call-reading part of :class:`~.sources_cpp._File` (module docstring)."""

    if TYPE_CHECKING:  # the file reader's state and helpers the mixin reads, declared for the type checker only
        def __getattr__(self, name: str) -> Any: ...

    def call(self, n: Any) -> None:
        """One call expression: a node name, a construction, a helper's
        endpoints, an action, a service call, or an endpoint method."""
        fn = n.child_by_field_name("function")
        a = n.child_by_field_name("arguments")
        args = list(a.named_children) if a is not None else []
        if fn is None:
            return
        full, last, targs = callee_parts(fn)
        recv = fn.child_by_field_name("argument") if fn.type == "field_expression" else None
        s = self.scope
        if full == "ros::init" and len(args) >= 3:
            self.node(s.value(args[2]), n)
            return
        if last in ("make_shared", "make_unique", "allocate_shared") and targs and recv is None:
            self.construct(targs[0], args, n)
            return
        if full.endswith("Node::make_shared") and args:
            self.node(s.value(args[0]), n, s.value(args[1]) if len(args) > 1 else None,
                      "lifecycle" if "LifecycleNode" in full else None, args)
            return
        if full.endswith("Options::create") or (last == "init" and recv is not None and targs):
            return  # options: read where subscribe(ops) / advertise(ops) uses them
        specs = cpp_helpers.free(full, targs, args, s.value, self.aliases) if recv is None else None
        if specs is None and recv is not None:
            rt = s.type_of(recv)
            if rt is not None:
                specs = cpp_helpers.method(rt, last, args, targs, s.value, s.value(recv), self.aliases)
            elif not targs and self.helper_form(last, args) and self.deferred_method(recv, last, args, n) \
                    and last != "init":  # obj.init(...) may also be a method of the program's own class
                return
        if specs is not None:
            self.specs(specs, n)
            return
        if last in ("create_server", "create_client") and "rclcpp_action" in full:
            self.action2(last, targs, args, n)
            return
        if recv is not None and last in _INIT and args and self.init_spec(n, _INIT[last], args[0]):
            return
        if full in ("ros::service::call",) and len(args) >= 2:
            self.emit("service_clients", args[0], service_type(s.type_of(args[1])), n, None)
            return
        self.endpoint_call(n, full, last, targs, recv, args)

    def endpoint_call(self, n: Any, full: str, last: str, targs: list[str], recv: Any, args: list[Any]) -> None:
        """A call named as an endpoint method (:data:`_CALLS`) on a node, a
        handle or a stack's factory; any other call of the program's own code
        is recorded for the linker."""
        s = self.scope
        kind = _CALLS.get(last)
        if kind is not None and targs and last.startswith("create_") and self.interface_spec(n, kind, targs[0], args):
            return
        if kind is None or not args:
            if not full.startswith(LIBRARY):
                self.record("call", full, args, n)
                if targs:  # a function template's types, read in its body by the linker
                    owner = s.fn_of(n)
                    self.out.setdefault("call_targs", []).append(
                        (full, owner.unit if owner else None, owner.key if owner else None, len(args), targs))
            return
        if last == "create_server":
            return
        if recv is not None and last in _TEMPLATED and not targs:
            # rclcpp cannot deduce the message or service type of these methods (a template parameter
            # the call must give): one called without template arguments is a user's method of the
            # same name (leds_[i]->create_subscription(nh_, "led")), followed by the linker
            self.user_create(n, full, args)
            return
        if recv is not None and last.startswith("create_") and s.is_handle(args[0]):
            # rclcpp's node methods never take a node first: a user's method of the same name
            # (bus.create_publisher(node, "t")), followed by the linker into its body
            self.user_create(n, full, args)
            return
        if recv is None and "::" in full and not self.rclcpp_like(full, args, n):
            # ns::create_subscription<T>(topic, ...): no node is given and ns is no rclcpp class:
            # a workspace's function, followed by the linker into its body, else a note
            self.user_create(n, full, args, "is a function of another namespace than rclcpp's, given no node")
            return
        handle = s.value(recv) if recv is not None else None
        if recv is None and last.startswith("create_") and len(args) >= 2 and (
                s.is_handle(args[0]) or self.generic_node(args[0])):
            # a stack's factory, qualified or not: ns::create_service<T>(node, name, ...), read at its call
            handle, args = s.value(args[0]), args[1:]
        if last in ("advertise", "subscribe") and len(args) >= 2 and s.is_handle(args[0]):
            # advertise(nh, topic, n) / subscribe(nh, topic, n) of an object given the handle
            # (topic_tools::ShapeShifter, a message_filters subscriber of a class this file does not know)
            ta = targs[0] if targs else None
            self.emit(kind, args[1], self.msg(ta) if ta else None, n, s.value(args[0]))
            return
        if len(args) == 1 and last in ("subscribe", "advertise", "advertiseService") and "::" in full and recv is None:
            return  # a static method of some class (T::subscribe(rate)), not a node handle's
        if len(args) == 1 and last in ("subscribe", "advertise", "advertiseService"):
            self.from_options(n, last, args[0], handle)
            return
        if last in ("create_generic_publisher", "create_generic_subscription"):
            gt = s.value(args[1]) if len(args) > 1 else None
            self.emit(kind, args[0], canon_type(symbols.text(gt)) if gt and gt[0] == "str" else None, n, handle)
            return
        self.typed_endpoint(n, kind, last, targs, args, handle)

    def interface_spec(self, n: Any, kind: str, spec: str, args: list[Any]) -> bool:
        """``adaptor.create_publisher<Spec>()``, ``create_service<Spec>(this, &cb)``,
        ``create_subscription<Spec>(cb)``: an interface-spec adaptor (Autoware's
        component_interface_utils), whose template argument is a struct holding
        the name (``static constexpr char name[] = "/api/..."``) and the type
        (``using Message = ...`` / ``using Service = ...``), when the call
        gives no name first (no argument, ``this``, a member pointer, a
        lambda, ``std::bind``).  A spec this file defines is read here; one of
        another file of the program (a header, another package's) is left to
        the linker (``Spec::name`` as a class member, ``Spec::Message`` as an
        alias), which says at the call what it cannot read.  Returns whether
        the call was handled."""
        key = spec.replace(" ", "").lstrip(":")
        hits = [k for k in self.spec_names if k == key or k.endswith("::" + key)]
        if len(hits) == 1:
            full = hits[0]
            if kind in ("pub", "sub"):
                t = self.msg(self.aliases.get(f"{full}::Message"))
            else:
                t = service_type(self.aliases.get(f"{full}::Service"))
            name = self.spec_names[full]
            self.emit(kind, None, t, n, None, name=symbols.lit(name), written=name)
            return True
        first = args[0] if args else None
        if first is not None and not (first.type in ("this", "lambda_expression", "pointer_expression")
                                      or _T(first).startswith(("std::bind", "&"))):
            return False  # rclcpp's own form: the name first
        # a spec of another file (a header, another package's): its name and type read by the linker
        member = "Message" if kind in ("pub", "sub") else "Service"
        self.emit(kind, None, None, n, None, cb=("spec", f"{key}::{member}"), name=("spec", key),
                  written=f"{key}::name")
        return True

    def init_spec(self, n: Any, kind: str, member: Any) -> bool:
        """``adaptor.init_pub(pub_)`` (``init_sub``, ``init_srv``, ``init_cli``) of
        component_interface_utils: the member, declared ``Publisher<Spec>::SharedPtr``
        in its class, is made with ``Spec``'s name and type; left to the linker
        (``("specof", class, member)``), which reads the member's declaration."""
        fn = self.scope.fn_of(n)
        name = _T(member).replace("this->", "").strip()
        if fn is None or not fn.in_class or not name.isidentifier():
            return False
        v = ("specof", fn.unit, name)
        self.emit(kind, None, None, n, None, cb=v, name=v, written=f"{name} (interface spec)")
        return True

    def user_create(self, n: Any, full: str, args: list[Any], *why: str) -> None:
        """A ``create_*`` call that is the program's own function or method:
        recorded for the linker, which follows it into its body."""
        self.record("call", full, args, n)
        owner = self.scope.fn_of(n)
        self.out.setdefault("user_creates", []).append(
            (full, owner.unit if owner else None, owner.key if owner else None, self.src(n), *why))

    def from_options(self, n: Any, last: str, arg: Any, handle: Any) -> None:
        """``subscribe(ops)`` / ``advertise(ops)`` / ``advertiseService(ops)``:
        the endpoint the options object describes, else a note."""
        ops = self.scope.value(arg)
        if ops is not None and ops[0] == "ops":
            t = self.msg(ops[3]) if ops[1] in ("pub", "sub") else service_type(self.aliases.get(ops[3], ops[3]))
            ocb = callback_name(ops[4] or "") or None
            if t is None and ocb:
                ct = self.out["callbacks"].get(ocb)
                t = self.msg(ct) if ops[1] in ("pub", "sub") else service_type(ct)
            self.emit(ops[1], None, t, n, handle, ocb if t is None else None, name=ops[2],
                      written=ops[5] if len(ops) > 5 else None)
        else:
            self.out["notes"].append(Note(self.src(n), f"{last}({_T(arg)[:60]}): its options are not read "
                                                       f"statically"))

    def typed_endpoint(self, n: Any, kind: str, last: str, targs: list[str], args: list[Any], handle: Any) -> None:
        """An endpoint whose type is its template argument, else its callback's
        parameter (in this file, or by the linker)."""
        ta = targs[0] if targs else None
        cb: Any = None
        if kind in ("pub", "sub"):
            msg_type = self.msg(ta) if ta else None
            if msg_type is None and kind == "sub" and last == "subscribe" and len(args) >= 3:
                cb = callback_name(_T(args[2]))
                msg_type = self.msg(self.out["callbacks"].get(cb))
        else:
            msg_type = service_type(self.aliases.get(ta, ta) if ta else None)
            if msg_type is None and last == "advertiseService" and len(args) >= 2:
                cb = callback_name(_T(args[1]))
                msg_type = service_type(self.out["callbacks"].get(cb))
        if msg_type is None and cb is None and ta:
            cb = ("type", ta)  # an alias of another file (a header's using/typedef): read by the linker
        self.emit(kind, args[0], msg_type, n, handle, cb if msg_type is None else None)

    def action2(self, last: str, targs: list[str], args: list[Any], n: Any) -> None:
        """``rclcpp_action::create_server<T>`` / ``create_client<T>`` with a
        node before the name, or node interfaces (four for a server: base,
        clock, logging, waitables; three for a client: base, graph, logging).
        rclcpp_action's overloads tell them apart by count: a server given a
        node takes at most 7 arguments, given interfaces at least 8; a client
        given a node at most 4, given interfaces at least 4 (at 4, a first
        argument written as an interface decides)."""
        kind = "action_servers" if last == "create_server" else "action_clients"
        named = "interface" in _T(args[0]) if args else False
        if kind == "action_servers":
            k = 4 if len(args) >= 8 or (len(args) >= 5 and named) else 1
        else:
            k = 3 if len(args) >= 5 or (len(args) == 4 and named) else 1
        if len(args) <= k:
            return
        t = action_type(self.aliases.get(targs[0], targs[0])) if targs else None
        self.emit(kind, args[k], t, n, self.scope.value(args[0]) if k == 1 else None,
                  ("type", targs[0]) if t is None and targs else None)
