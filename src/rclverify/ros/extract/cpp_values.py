"""The value of a C++ name expression in its file's scopes (:mod:`cpp_scope`;
docs/ros.md, "Reading real code").

:meth:`CppValues.value` gives an expression's :mod:`symbols` value: a
literal (``"x"``, ``std::string(X)``, a constant or ``#define``, a
concatenation), a parameter of the enclosing function (``("arg", key, i)``),
a member of its class (``("field", class, name)``, bound where the program
constructs it), a ROS parameter read (:mod:`cpp_params`), a node handle
(``ros::NodeHandle nh("~")``, ``ros::NodeHandle(parent, "ns")``, rclcpp
``create_sub_node("ns")``, a nodelet's ``getPrivateNodeHandle()``), the node's
own name (``ros::this_node::getName()``, ``get_fully_qualified_name()``,
rclcpp's ``get_name()``), a parameter read with a computed key, a name
resolved or expanded by rclcpp for the node (``node_base->
resolve_topic_or_service_name("image", false)``,
``rclcpp::expand_topic_or_service_name(name, get_name(), get_namespace())``:
the name as written, which the graph resolves as ROS does; one that is
relative and follows other text in a concatenation is not read),
roscpp options (``ros::SubscribeOptions::create<T>(name, ...)``,
``ops.init<T>(name, ...)``).  A name bound twice to different values is not
read (``None``).
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import symbols, treesitter
from rclverify.ros.extract.cpp_params import KEY, param_read, string_value
from rclverify.ros.extract.cpp_names import base_name, is_node_type
from rclverify.ros.extract.cpp_scope import _HANDLE_TYPES, MAX_DEPTH, CppScope, Fn

_T = treesitter.text
#: namespaces of libraries whose functions the workspace does not define: their calls are not followed
_LIBRARY = ("std::", "ros::", "rclcpp", "boost::", "tf2", "Eigen::", "rcutils_", "rcl_", "rmw_", "cv::", "pcl::")

#: rclcpp's name resolution for a node: ``NodeBaseInterface::resolve_topic_or_service_name``
#: (rclcpp >= Humble) and ``rclcpp::expand_topic_or_service_name`` (name, node name, namespace).
_RESOLVERS = ("resolve_topic_or_service_name", "expand_topic_or_service_name")

#: rclcpp::NodeOptions' setters, each returning the options (rclcpp/node_options.hpp)
_OPTION_SETTERS = ("use_intra_process_comms", "use_global_arguments", "enable_rosout", "start_parameter_services",
                   "start_parameter_event_publisher", "allow_undeclared_parameters", "parameter_overrides",
                   "append_parameter_override", "automatically_declare_parameters_from_overrides", "context",
                   "enable_topic_statistics", "use_clock_thread")

_OPTIONS = {"SubscribeOptions": "sub", "AdvertiseOptions": "pub", "AdvertiseServiceOptions": "service_servers"}


def _options(ftext: str, fn: Any, args: list[Any]) -> tuple[str, str] | None:
    """``(role, type text)`` of roscpp's ``ros::SubscribeOptions::create<T>(name, ...)``
    or ``ops.init<T>(name, ...)`` (also ``AdvertiseOptions``, ``AdvertiseServiceOptions``)."""
    if not args or "<" not in ftext:
        return None
    head = ftext.split("<")[0]
    tpl = ftext[ftext.index("<") + 1: ftext.rindex(">")] if ">" in ftext else ""
    parts = head.split("::")
    if len(parts) >= 2 and parts[-1] == "create" and parts[-2] in _OPTIONS:
        return _OPTIONS[parts[-2]], tpl
    return None



class CppValues(CppScope):
    """A file's scopes with the values of its expressions; ``nodelet``: whether the
    file is a nodelet's (``getName()`` is then the node's own name)."""

    nodelet = False

    def value(self, n: Any, depth: int = 0) -> symbols.Val:
        """The :mod:`symbols` value of expression ``n`` (``None``: not read statically)."""
        if n is None or depth > MAX_DEPTH:
            return None
        t = n.type
        s = string_value(n)
        if s is not None:
            return symbols.lit(s)
        if t == "concatenated_string":
            parts = [string_value(c) for c in n.named_children]
            return symbols.lit("".join(p for p in parts if p is not None)) if None not in parts else None
        if t in ("parenthesized_expression",) and n.named_children:
            return self.value(n.named_children[0], depth + 1)
        if t == "binary_expression" and _T(n.child_by_field_name("operator")) == "+":
            if self._resolved_relative(n.child_by_field_name("right"), depth):
                return None  # "ns" + resolve("x"): the node's namespace in the middle of a name
            return symbols.cat([self.value(n.child_by_field_name("left"), depth + 1),
                                self.value(n.child_by_field_name("right"), depth + 1)])
        if t == "call_expression":
            return self._call_value(n, depth)
        if t == "this":
            return ("nh", ())
        if t in ("identifier", "field_expression", "pointer_expression", "qualified_identifier"):
            return self._name_value(n, depth)
        if t == "subscript_expression" and _T(n.child_by_field_name("argument")) == "argv":
            return ("runtime", "from argv")  # main's argv[i]: the command line (symbols)
        if t == "subscript_expression":  # options.arguments()[0]
            idx = n.child_by_field_name("indices") or n.child_by_field_name("index")
            if idx is not None and idx.type == "subscript_argument_list" and idx.named_children:
                idx = idx.named_children[0]
            return self._option_arg(n.child_by_field_name("argument"), idx, depth)
        return None

    def _option_arg(self, recv: Any, idx: Any, depth: int) -> symbols.Val:
        """``("optarg", options, i)`` for ``options.arguments()[i]`` (``.at(i)``,
        ``.front()`` when ``idx`` is ``None``): a node name passed in
        ``rclcpp::NodeOptions::arguments`` and read back in the constructor."""
        if recv is None or recv.type != "call_expression":
            return None
        f = recv.child_by_field_name("function")
        if f is None or f.type != "field_expression" or _T(f.child_by_field_name("field")) != "arguments":
            return None
        try:
            i = int(_T(idx)) if idx is not None else 0
        except ValueError:
            return None
        opts = self.value(f.child_by_field_name("argument"), depth + 1)
        return ("optarg", opts, i) if opts is not None else None

    def _call_value(self, n: Any, depth: int) -> symbols.Val:
        fn = n.child_by_field_name("function")
        a = n.child_by_field_name("arguments")
        args = list(a.named_children) if a is not None else []
        ftext = _T(fn)
        last = ftext.split("::")[-1].split(".")[-1].split(">")[-1]
        if ftext.endswith("this_node::getName") or last == "get_fully_qualified_name":
            return symbols.NODE
        if ftext == "getName" and not args and self.nodelet:  # nodelet::Nodelet::getName(): the node's name
            return symbols.NODE
        if last == "get_name" and not args and (fn.type != "field_expression" or self.is_handle(
                fn.child_by_field_name("argument"))):
            # rclcpp's Node::get_name(): the node's name without its namespace; a name
            # made from it (get_name() + "/x") is relative, so it resolves as ~/x
            return symbols.NODE
        if ftext in ("std::string", "string", "std::string_view") and len(args) == 1:
            return self.value(args[0], depth + 1)
        if last in _RESOLVERS and args:
            # rclcpp resolves (remaps) the name against the node: what the graph does with it as written
            return self.value(args[0], depth + 1)
        if base_name(ftext) in _HANDLE_TYPES:
            return self.handle(args, depth)
        if last == "create_sub_node" and len(args) == 1 and (fn is None or fn.type != "field_expression"):
            return ("nh", (("ns", self.value(args[0], depth + 1)),))
        if last in ("getPrivateNodeHandle", "getMTPrivateNodeHandle"):
            return ("nh", (("ns", symbols.lit("~")),))
        if last in ("getNodeHandle", "getMTNodeHandle", "shared_from_this"):
            return ("nh", ())
        if fn is not None and fn.type == "field_expression":
            method = _T(fn.child_by_field_name("field"))
            recv = fn.child_by_field_name("argument")
            if method in ("c_str", "str", "data", "as_string_array") and not args:
                return self.value(recv, depth + 1)
            if not args and recv is not None and recv.type == "call_expression":
                inner = self.value(recv, depth + 1)  # get_parameter("t").as_string(), wrapper(node, "t").get<T>()
                if inner is not None and inner[0] in ("param", "ret"):
                    return inner
            if method == "arguments" and len(args) == 1 and args[0].type == "initializer_list":
                return ("opts", tuple(self.value(x, depth + 1) for x in args[0].named_children))  # NodeOptions
            if method in ("at", "front") and len(args) <= 1 and recv is not None:
                return self._option_arg(recv, args[0] if args else None, depth)
            if method in _OPTION_SETTERS and recv is not None:  # NodeOptions().arguments(...).use_...(true)
                inner = self.value(recv, depth + 1)
                if inner is not None and inner[0] == "opts":
                    return inner
            if method == "create_sub_node" and len(args) == 1:
                return ("nh", (("h", self.value(recv, depth + 1)), ("ns", self.value(args[0], depth + 1))))
        ops = _options(ftext, fn, args)
        if ops is None and fn is not None and fn.type == "field_expression" and args and "<" in ftext \
                and ftext.split("<")[0].endswith(("init",)):
            rt = base_name(self.type_of(fn.child_by_field_name("argument")) or "")
            if rt in _OPTIONS:
                ops = (_OPTIONS[rt], ftext[ftext.index("<") + 1: ftext.rindex(">")])
        if ops is not None:
            return ("ops", ops[0], self.value(args[0], depth + 1), ops[1], _T(args[2]) if len(args) > 2 else None,
                    _T(args[0]))
        r = param_read(n)
        if r is not None:
            pname, default, _ref, recv, ros2 = r
            if default is None and ros2:
                default = self.declared.get(pname)
            if default is None and ros2 and ftext.split("<")[0].endswith("declare_parameter") and len(args) >= 2:
                default = self._symbolic_default(args[1], depth)
            if pname.startswith(KEY):  # a computed key: its value, read here or by the linker
                key = self.value(args[0], depth + 1)
                text = symbols.text(key) if key is not None and symbols.is_concrete(key) else None
                if key is None or key[0] in ("node", "param") or text is not None and text.startswith("~"):
                    return None
                return ("param", "~" + text if text is not None else key, default, None)
            return ("param", pname, default, self.value(recv, depth + 1) if recv is not None and not ros2 else None)
        return self._returned(n, fn, args, depth)

    def _symbolic_default(self, n: Any, depth: int) -> symbols.Val:
        """The default a ``declare_parameter(name, x)`` is given when ``x`` is no
        literal but a value the linker may read (a parameter of a wrapper
        function, also as ``rclcpp::ParameterValue(x)`` / ``ParameterValue{x}``);
        ``None`` otherwise."""
        if n.type in ("call_expression", "compound_literal_expression"):
            head = _T(n.child_by_field_name("function") or n.child_by_field_name("type"))
            a = n.child_by_field_name("arguments") or n.child_by_field_name("value")
            if head.split("::")[-1] != "ParameterValue" or a is None or len(a.named_children) != 1:
                return None
            n = a.named_children[0]
        v = self.value(n, depth + 1)
        return v if v is not None and not symbols.is_concrete(v) else None

    def _returned(self, n: Any, fn: Any, args: list[Any], depth: int) -> symbols.Val:
        """``("ret", callee, unit, args)`` for a call of a function the workspace
        may define (a free function, or a method of this object or of a node),
        read by the linker from the callee's ``return`` statements; ``None`` for
        a library's function or a method of another object."""
        if fn is None:
            return None
        head = _T(fn).replace("template ", "").split("<")[0].strip()
        if not head or head.startswith(_LIBRARY) or fn.type not in ("identifier", "qualified_identifier",
                                                                   "template_function", "field_expression"):
            return None
        if fn.type == "field_expression":
            recv = fn.child_by_field_name("argument")
            if recv is None or not (recv.type == "this" or self.is_handle(recv)):
                rv = self.value(recv, depth + 1) if recv is not None else None
                if rv is None or rv[0] != "nh":  # auto node = shared_from_this(): a node too
                    return None
        owner = self.fn_of(n)
        return ("ret", head, owner.unit if owner is not None else None,
                tuple(self.value(a, depth + 1) for a in args))

    def handle(self, args: list[Any], depth: int = 0) -> symbols.Val:
        """A ``ros::NodeHandle`` made with constructor arguments ``args``: ``()``,
        ``(ns)``, ``(parent, ns)``, ``(ns, remappings)``, or a copy ``(other)``."""
        if not args:
            return ("nh", ())
        first = self.value(args[0], depth + 1)
        if len(args) >= 2 and self.is_handle(args[0]):
            return ("nh", (("h", first), ("ns", self.value(args[1], depth + 1))))
        if self.is_handle(args[0]):
            return ("nh", (("h", first),))
        return ("nh", (("ns", first),))

    def is_handle(self, n: Any) -> bool:
        """Whether expression ``n`` is a node handle or node: declared with a handle
        or node type, ``this``, ``shared_from_this()``, a ``NodeHandle(...)``."""
        t = n.type
        if t == "this" or (t == "pointer_expression" and _T(n).lstrip("*&") == "this"):
            return True
        if t == "call_expression":
            f = _T(n.child_by_field_name("function"))
            return base_name(f) in _HANDLE_TYPES or f.endswith(("shared_from_this", "create_sub_node",
                                                                 "getNodeHandle", "getPrivateNodeHandle",
                                                                 "getMTNodeHandle", "getMTPrivateNodeHandle"))
        if t in ("identifier", "field_expression", "pointer_expression"):
            return is_node_type(self.type_of(n) or "")
        return False

    def _resolved_relative(self, n: Any, depth: int) -> bool:
        """Whether expression ``n`` is (or is a local bound only to) an rclcpp name
        resolution (:data:`_RESOLVERS`) of a name that is not absolute: the node's
        namespace then comes first in its text, which no written form can say."""
        if n is None or depth > MAX_DEPTH:
            return False
        if n.type == "call_expression":
            fn = n.child_by_field_name("function")
            last = _T(fn).split("::")[-1].split(".")[-1].split(">")[-1]
            a = n.child_by_field_name("arguments")
            if last in _RESOLVERS and a is not None and a.named_children:
                txt = symbols.text(self.value(a.named_children[0], depth + 1))
                return not (txt or "").startswith("/")
            return False
        f = self.fn_of(n) if n.type == "identifier" else None
        binds = self.locals.get((f.nid, _T(n)), []) if f is not None else []
        return any(not isinstance(b, tuple) and self._resolved_relative(b, depth + 1) for b in binds)

    def _name_value(self, n: Any, depth: int) -> symbols.Val:
        fn = self.fn_of(n)
        t = n.type
        if t == "pointer_expression":
            if _T(n).lstrip("*&") == "this":
                return ("nh", ())
            return self.value(n.named_children[-1], depth + 1) if n.named_children else None
        if t == "field_expression":
            part = _T(n.child_by_field_name("field"))
            if part in ("first", "second") and _T(n.child_by_field_name("argument")) != "this":
                pairs = self.value(n.child_by_field_name("argument"), depth + 1)  # kv.second over a map
                if pairs is not None and pairs[0] == "any" and all(x[0] == "pair" for x in pairs[1]):
                    return ("any", tuple(x[1][part == "second"] for x in pairs[1]))
                return None
            if _T(n.child_by_field_name("argument")) != "this" or fn is None:
                return None
            return self._member(fn, _T(n.child_by_field_name("field")), depth)
        name = _T(n)
        if t == "qualified_identifier":
            vals = self.consts.get(name) or self.consts.get("::".join(name.split("::")[-2:])) or []
            return self._one([self.value(v, depth + 1) if not isinstance(v, tuple) else v for v in vals])
        if fn is not None:
            if name in fn.params:
                v = ("arg", fn.key, fn.params.index(name))
                return ("nh", (("h", v),)) if is_node_type(fn.ptypes[fn.params.index(name)]) else v
            key = (fn.nid, name)
            if key in self.ltypes or key in self.locals:
                return self._local(fn, self.locals.get(key, []), depth)
            if fn.in_class and name not in self.consts:
                return self._member(fn, name, depth)
        if name in self.consts:
            return self._one([self.value(v, depth + 1) if not isinstance(v, tuple) else v for v in self.consts[name]])
        return None

    def _local(self, fn: Fn, binds: list[Any], depth: int) -> symbols.Val:
        """A local variable's value from its bindings in order.  A parameter read
        into it (``get_parameter("t", topic)``, ``getParam``) leaves it unchanged
        when the parameter is not set: what it held before is the read's default
        ("no default" was said where the code assigns one first)."""
        reads = [i for i, b in enumerate(binds) if isinstance(b, tuple) and b and b[0] == "read"]
        if not reads or reads[-1] == 0:
            return self._one([self._bound(fn, b, depth) for b in binds])
        i = reads[-1]
        v = self._bound(fn, binds[i], depth)
        if v is not None and v[0] == "param" and v[2] is None:
            prior = self._one([self._bound(fn, b, depth) for b in binds[:i]])
            if prior is not None and prior[0] == "str":
                v = (v[0], v[1], prior[1], *v[3:])
        return self._one([v] + [self._bound(fn, b, depth) for b in binds[i + 1:]])

    def _member(self, fn: Fn, name: str, depth: int) -> symbols.Val:
        v = ("field", fn.unit, name)
        ty = self.classes.get(fn.unit, {}).get("members", {}).get(name)
        return ("nh", (("h", v),)) if ty is not None and is_node_type(ty) else v

    def _bound(self, fn: Fn | None, b: Any, depth: int) -> symbols.Val:
        if isinstance(b, tuple):
            if b[0] == "unknown":  # changed in place (snprintf, +=, append): not read
                return None
            if b[0] == "out":  # given to a function that writes its parameter b[2] (an out-parameter)
                callee = b[1]
                return self._one([self._bound(callee, x, depth + 1)
                                  for x in self.locals.get((callee.nid, b[2]), [])]) if depth < MAX_DEPTH else None
            if b[0] == "nhargs":
                return self.handle(b[1], depth + 1)
            if b[0] == "elems":  # a container, not a name
                return None
            if b[0] == "each" and (len(b) > 2 or self._elements(b[1], depth) is not None):
                return self._element(b, depth)
            if b[0] == "each":  # an element of a string-array parameter (symbols.each)
                arr = self.value(b[1], depth + 1)
                return ("each", arr[1]) if arr is not None and arr[0] == "param" and isinstance(arr[1], str) \
                    and not arr[1].startswith(KEY) else None
            if b[0] in ("read", "ops"):
                return self._call_value(b[1], depth + 1)
            if b[0] == "init":
                if len(b[1]) == 1 and not (fn is not None and is_node_type(
                        self.classes.get(fn.unit, {}).get("members", {}).get(b[2], ""))):
                    return self.value(b[1][0], depth + 1)
                return self.handle(b[1], depth + 1)
            return b
        return self.value(b, depth + 1)

    def _elements(self, n: Any, depth: int) -> list[Any] | None:
        """The element expressions of a container of literals a range-for iterates:
        ``{"a", "b"}`` itself, or a local bound once to one (``std::vector<std::string>
        names{"a", "b"}``, ``std::map<std::string, std::string> m{{"k", "t"}}``);
        ``None`` for anything else."""
        if n is None or depth > MAX_DEPTH:
            return None
        if n.type == "initializer_list":
            return list(n.named_children)
        f = self.fn_of(n) if n.type == "identifier" else None
        binds = self.locals.get((f.nid, _T(n)), []) if f is not None else []
        if len(binds) == 1 and isinstance(binds[0], tuple) and binds[0][0] == "elems":
            inner = binds[0][1]
            kids = list(inner.named_children)
            if len(kids) == 1 and kids[0].type == "initializer_list" and all(
                    k.type == "initializer_list" for k in kids[0].named_children):
                kids = list(kids[0].named_children)  # m{{{"k", "t"}, ...}} written with one more brace
            return kids
        return None

    def _element(self, b: tuple[Any, ...], depth: int) -> symbols.Val:
        """A range-for variable over a container of literals (:meth:`_elements`):
        ``("any", values)`` of its elements, or of part ``b[2]`` of each pair (a
        structured binding ``[key, topic]``); a pair element is ``("pair", (k, v))``."""
        elems = self._elements(b[1], depth) or []
        vals: list[symbols.Val] = []
        for el in elems:
            if el.type == "initializer_list" and len(el.named_children) == 2:
                pair = tuple(self.value(x, depth + 1) for x in el.named_children)
                vals.append(pair[b[2]] if len(b) > 2 and b[2] < 2 else ("pair", pair))
            else:
                vals.append(self.value(el, depth + 1) if len(b) == 2 else None)
        return ("any", tuple(vals)) if vals and all(v is not None for v in vals) else None

    @staticmethod
    def _one(vals: list[symbols.Val]) -> symbols.Val:
        got = set(vals)
        return next(iter(got)) if len(got) == 1 else None

    def field_values(self) -> dict[tuple[str, str], list[symbols.Val]]:
        """``{(class, member): [value, ...]}``: what each member is initialised or
        assigned with in this file (values relative to the binding function)."""
        out: dict[tuple[str, str], list[symbols.Val]] = {}
        for key, binds in self.fields.items():
            for fn, b in binds:
                v = self._bound(fn, b, 0) if fn is not None or isinstance(b, tuple) else self.value(b)
                out.setdefault(key, []).append(v)
        return out

