"""Publishers, subscribers, services, actions and node names in C++ node
sources, read with tree-sitter's C++ grammar (``tree-sitter``, ``tree-sitter-cpp``).

Recognised (roscpp and actionlib, ROS 1; rclcpp and rclcpp_action, ROS 2):

* ``<h>.advertise<T>(topic, ...)``, ``<h>.subscribe<T>(topic, ...)``,
  ``<h>.subscribe(topic, n, cb)`` (the type from the callback's first
  parameter, :mod:`cpp_types`, found in this file or, by the linker, in the
  program's other files), ``subscribe(ops)``/``advertise(ops)`` with
  ``ros::SubscribeOptions::create<T>(...)`` / ``ops.init<T>(...)``;
  ``create_publisher<T>``, ``create_subscription<T>``,
  ``create_generic_publisher(topic, "pkg/msg/T")`` with any receiver;
* services: ``advertiseService(name, &cb)``, ``serviceClient<Srv>(name)``,
  ``ros::service::call(name, srv)``, ``create_service<Srv>``, ``create_client<Srv>``;
  actions: actionlib ``SimpleActionServer``/``SimpleActionClient`` (declared,
  members initialised in a constructor, ``new``, ``make_shared``; a leading
  node handle is skipped), ``rclcpp_action::create_server<T>`` /
  ``create_client<T>`` (node, name) or (four node interfaces, name);
* library helpers (:mod:`cpp_helpers`): tf, message_filters,
  image_transport, interactive markers, parameter events, ``waitForMessage``,
  also made by a default member initializer (``Sub<T> sub_{this, "t"}``);
  interface-spec adaptors (``adaptor.create_publisher<Spec>()``,
  ``adaptor.init_pub(pub_)``: :meth:`~.cpp_calls.CallReader.interface_spec`);
* endpoints alike in alternative ``#if``/``#elif``/``#else`` branches: one
  (:func:`~.cpp_prep.one_per_branch`);
* names (:mod:`cpp_scope`): literals, constants, parameters (:mod:`cpp_params`),
  and what only the program knows (a constructor argument, a member),
  left to the linker (:mod:`link`); node handles' namespaces;
* node names from ``ros::init(argc, argv, "n")``, ``Node("n"[, "ns"])``
  initialisers, ``rclcpp::Node node("n")``, ``std::make_shared<rclcpp::Node>("n")``,
  ``rclcpp::Node::make_shared("n")``;
* for the linker: functions and their parameters, classes (members, bases),
  calls and constructions with their argument values, member bindings,
  quoted ``#include``\\ s; the classes registered as components.

What a construction makes is read by :mod:`cpp_constructions`, what a
call makes by :mod:`cpp_calls`, what a class holds by :mod:`cpp_members`.
Text the grammar would misread is blanked first (:mod:`cpp_prep`).  A name
that is not read statically is reported unresolved at its location.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import cpp_helpers, emit, names, symbols, treesitter
from rclverify.ros.extract.cpp_calls import CallReader
from rclverify.ros.extract.cpp_constructions import ConstructionReader
from rclverify.ros.extract.cpp_members import MemberReader
from rclverify.ros.extract.cpp_prep import REGISTER, blank_if0, branches, one_per_branch, prepare
from rclverify.ros.extract.nodelets import registered
from rclverify.ros.extract.cpp_names import namespaces_of
from rclverify.ros.extract.cpp_values import CppValues
from rclverify.ros.extract.cpp_types import adapted, action_type, message_type, service_type
from rclverify.ros.extract.model import Note, Src

__all__ = ["scan_cpp", "action_type", "service_type"]

_T = treesitter.text


class _File(CallReader, MemberReader, ConstructionReader):
    def __init__(self, data: bytes, shown: str) -> None:
        self.shown = shown
        self.vex_at: Any = None
        self.out: dict[str, Any] = {"nodes": [], "endpoints": [], "notes": [], "classes": {}, "components": [],
                                    "lang": "cpp", "calls": [], "node_names": [], "member_decls": [],
                                    "member_calls": [], "includes": [], "callbacks": {}}
        data = blank_if0(data)  # code the preprocessor drops is never read
        self.branch = branches(data)
        for m in REGISTER.finditer(data):
            line = data.count(b"\n", 0, m.start()) + 1
            self.out["components"].append((m.group(1).decode().lstrip(":"), Src(shown, line, 1)))
        self.out["nodelets"] = registered(data, shown)
        adapters = adapted(data)
        data = prepare(data)
        self.ros2 = b"rclcpp" in data
        root = treesitter.parser("cpp").parse(data).root_node
        self.nodes = list(treesitter.walk(root))
        self.aliases: dict[str, str] = adapters
        self._bare: dict[str, set[str]] = {}  # an alias's bare name -> the texts the file gives it
        self.spec_names: dict[str, str] = {}  # interface spec struct -> its static name[] literal
        for n in self.nodes:
            self._index(n)
        self.scope = CppValues(self.nodes)
        self.scope.nodelet = b"nodelet" in data and b"Nodelet" in data
        if root.has_error:
            err = next((n for n in self.nodes if n.type == "ERROR" or n.is_missing), root)
            self.out["notes"].append(Note(self.src(err), "C++ source has syntax errors; read what tree-sitter "
                                                         "recovered", "ROS-PARSE"))

    def src(self, n: Any) -> Src:
        if self.vex_at is not None:  # an expression re-read out of place: located at its declaration
            n = self.vex_at
        return Src(self.shown, n.start_point[0] + 1, n.start_point[1] + 1)

    def _index(self, n: Any) -> None:
        t = n.type
        if t == "function_declarator":
            written = _T(n.child_by_field_name("declarator"))
            params = n.child_by_field_name("parameters")
            first = next((c for c in (params.children if params else [])
                          if c.type in ("parameter_declaration", "optional_parameter_declaration")), None)
            if first is not None and first.child_by_field_name("type") is not None:
                ty = _T(first.child_by_field_name("type"))
                _nss, cls = namespaces_of(n)
                # by its name as written, with its class, and alone (the last a fallback)
                for key in {written, "::".join(cls + [written]), written.split("::")[-1]}:
                    self.out["callbacks"].setdefault(key, ty)
        elif t == "alias_declaration":
            self._alias(n, _T(n.child_by_field_name("name")), _T(n.child_by_field_name("type")))
        elif t == "type_definition":
            for d in n.children_by_field_name("declarator"):
                self._alias(n, _T(d), _T(n.child_by_field_name("type")))
        elif t == "using_declaration" and not any(c.type == "namespace" for c in n.children) and n.named_children:
            full = _T(n.named_children[-1])
            self._alias(n, full.split("::")[-1], full)
        elif t == "field_declaration" and n.parent is not None and n.parent.type == "field_declaration_list":
            d, v = n.child_by_field_name("declarator"), n.child_by_field_name("default_value")
            if d is not None and d.type == "array_declarator" and _T(d).replace(" ", "") == "name[]" \
                    and v is not None and v.type == "string_literal" and "static" in _T(n).split():
                nss, cls = namespaces_of(n)  # an interface spec: static constexpr char name[] = "/api/...";
                self.spec_names["::".join(nss + cls)] = _T(v)[1:-1]
        elif t == "preproc_include":
            p = n.child_by_field_name("path")
            if p is not None:
                self.out["includes"].append(_T(p).strip('"<>'))

    def _alias(self, n: Any, name: str, text: str) -> None:
        """Alias ``name`` of ``text`` declared at syntax node ``n``: kept under its
        scope-qualified name (``ns::Cls::name``) and, while one text is all the
        file gives it, under its bare name too; a bare name two scopes give
        different texts is left out (each scope's stays: :func:`~.cpp_types.alias_of`
        reads it in the scope of its use, never one scope's for the other's)."""
        nss, cls = namespaces_of(n)
        if nss or cls:
            self.aliases["::".join(nss + cls + [name])] = text
        seen = self._bare.setdefault(name, set())
        seen.add(text)
        if len(seen) == 1:
            self.aliases[name] = text
        else:
            self.aliases.pop(name, None)

    def msg(self, text: str | None) -> str | None:
        t = message_type(text, self.aliases)
        msgs = [ns for ns in self.scope.using_ns if ns.endswith(("::msg", "_msgs"))]
        if t is None and text and "::" not in text and len(msgs) == 1:  # using namespace pkg::msg;
            t = message_type(f"{msgs[0]}::{text.strip()}", self.aliases)
        return t

    # -- emitting
    def emit(self, kind: str, name_node: Any, msg_type: str | None, at: Any, handle: symbols.Val,
             cb: Any = None, name: symbols.Val = "unset", written: str | None = None) -> None:
        v = self.scope.value(name_node) if name == "unset" else name
        fn = self.scope.fn_of(at)
        unit = fn.unit if fn is not None else None
        if written is None:
            written = _T(name_node) if name_node is not None else emit.short(str(symbols.text(v) or "?"))
        ep, note = emit.make(kind, v, handle, msg_type, self.src(at), unit, fn.key if fn else None, written,
                             self.src(name_node) if name_node is not None else self.src(at), cb)
        if note is not None:
            self.out["notes"].append(note)
        if ep is None:
            return
        if ep.pending is None and ep.msg_type is None:
            self.out["notes"].append(emit.type_note(ep))
        self.out["endpoints"].append(ep)
        if fn is not None and fn.in_class:
            self.out["classes"].setdefault(fn.unit, {"nodes": [], "endpoints": []})["endpoints"].append(ep)

    def specs(self, specs: list[cpp_helpers.Spec], at: Any) -> None:
        for kind, v, t, h in specs:
            self.emit(kind, None, t, at, h, name=v)

    def node(self, v: symbols.Val, at: Any, ns: symbols.Val = None, kind: str | None = None,
             args: list[Any] | None = None) -> None:
        """A node named ``v`` (in namespace ``ns``) at ``at``; ``args``: the node
        constructor's arguments, whose last (after the name) may be the
        ``NodeOptions`` whose remaps rename it (read by the linker)."""
        fn = self.scope.fn_of(at)
        unit = fn.unit if fn is not None else None
        t = symbols.text(v)
        if t is not None and symbols.is_concrete(v) and v[0] != "node" and names.node_name_problem(t) is None:
            self.out["nodes"].append((t, self.src(at)))
            if fn is not None and fn.in_class:
                self.out["classes"].setdefault(fn.unit, {"nodes": [], "endpoints": []})["nodes"].append(
                    (t, self.src(at)))
        opts = self.scope.value(args[-1]) if args is not None and len(args) >= 2 else None
        if opts is not None and opts[0] in ("str", "cat"):
            opts = None
        self.out["node_names"].append((v, self.src(at), unit, fn.key if fn else None, ns, kind, opts))

    def record(self, kind: str, callee: str, args: list[Any], at: Any) -> None:
        fn = self.scope.fn_of(at)
        vals = [self.scope.value(a) for a in args]
        self.out["calls"].append((kind, callee, vals, fn.key if fn else None, fn.unit if fn else None,
                                  self.src(at)))

    # -- the walk
    def run(self) -> dict[str, Any]:
        for n in self.nodes:
            t = n.type
            if t == "field_initializer":
                self.initializer(n)
            elif t == "new_expression":
                a = n.child_by_field_name("arguments")
                self.construct(_T(n.child_by_field_name("type")), list(a.named_children) if a is not None else [], n)
            elif t == "declaration":
                self.declaration(n)
            elif t == "field_declaration":
                self.member(n)
            elif t in ("class_specifier", "struct_specifier"):
                self.bases(n)
            elif t == "call_expression":
                self.call(n)
        self.one_per_branch()
        s = self.scope
        # how many trailing parameters have a default (read or not): which overload a call picks
        self.out["optional"] = {f.key: sum(d is not None for d in f.defaults)
                                for f in list(s.decls.values()) + list(s.fns.values())}
        self.out["fns"] = {f.key: (f.unit, f.params, f.ptypes, [s.value(d) for d in f.defaults])
                           for f in list(s.decls.values()) + list(s.fns.values())}
        self.out["returns"] = self.returns()
        self.out["fn_tparams"] = {s.fns[n.id].key: _tparams(n.parent) for n in self.nodes
                                  if n.type == "function_definition" and n.id in s.fns and n.parent is not None
                                  and n.parent.type == "template_declaration"}
        self.out["aliases"] = self.aliases
        self.out["units"] = {c: {"bases": i["bases"], "members": i["members"], "tparams": i.get("tparams", []),
                                 "refs": i.get("refs", [])} for c, i in s.classes.items()}
        self.out["fields"] = s.field_values()
        self.out["consts"] = {k: v for k, v in ((k, s._one([s.value(x) if not isinstance(x, tuple) else x
                                                             for x in vs])) for k, vs in s.consts.items())
                              if v is not None}
        self.out["ros2"], self.out["using_ns"] = self.ros2, s.using_ns
        return self.out

    def one_per_branch(self) -> None:
        """Endpoints alike created in alternative ``#if`` branches: one (:func:`~.cpp_prep.one_per_branch`)."""
        kept = one_per_branch(self.out["endpoints"], self.branch)
        if len(kept) < len(self.out["endpoints"]):
            ids = {id(e) for e in kept}
            self.out["endpoints"] = kept
            for c in self.out["classes"].values():
                c["endpoints"] = [e for e in c["endpoints"] if id(e) in ids]

    def rclcpp_like(self, full: str, args: list[Any], n: Any) -> bool:
        """Whether qualified call ``full(args)`` may be rclcpp's (a create/advertise
        call): a factory given the node first, rclcpp's or roscpp's own name, or a
        node class's method named through its class (``rclcpp::Node::create_publisher``,
        the caller's own class or a base of it)."""
        if not full.split("::")[-1].startswith("create_") or full.startswith(("rclcpp", "ros::")):
            return True
        if len(args) >= 2 and (self.scope.is_handle(args[0]) or self.generic_node(args[0])):
            return True
        qual = full.rsplit("::", 1)[0].split("::")[-1].split("<")[0]
        owner = self.scope.fn_of(n)
        bases = self.scope.classes.get(owner.unit, {}).get("bases", []) if owner is not None else []
        return "Node" in qual or (owner is not None and qual == owner.unit.split("::")[-1]) or any(
            b.split("<")[0].split("::")[-1] == qual for b in bases)

    def generic_node(self, n: Any) -> bool:
        """Whether expression ``n`` is declared with a template parameter of its
        function or class (``template<typename NodeT> C(const NodeT & parent)``):
        given first to a stack's ``ns::create_subscription<T>(parent, topic, ...)``,
        it stands for the node of any kind the template is made with."""
        t = self.scope.type_of(n) if n.type == "identifier" else None
        if not t:
            return False
        base = t.replace("const", "").replace("&", "").replace("*", "").strip()
        p = n.parent
        while p is not None:
            if p.type == "template_declaration":
                ps = p.child_by_field_name("parameters")
                if base in _tparams(p):
                    return True
            p = p.parent
        return False

    def returns(self) -> dict[str, list[tuple[int, int, list[symbols.Val], list[symbols.Val], list[bool]]]]:
        """Per function key, one ``(parameters, defaulted ones, default values,
        values returned, per parameter: whether it may take a string literal)``
        per definition (overloads apart) that returns a value
        the linker may read: a ``("ret", ...)`` call of it is read from these
        (a ``declare_parameter`` wrapper).  A lambda's ``return`` is not
        its enclosing function's."""
        s, got = self.scope, {}  # type: ignore[var-annotated]
        self.nodes_by_id = {n.id: n for n in self.nodes if n.type == "function_definition"}
        for n in self.nodes:
            if n.type != "return_statement" or not n.named_children:
                continue
            p = n.parent
            while p is not None and p.type not in ("function_definition", "lambda_expression"):
                p = p.parent
            f = s.fns.get(p.id) if p is not None and p.type == "function_definition" else None
            if f is not None:
                got.setdefault(p.id, (f, []))[1].append(s.value(n.named_children[0]))
        out: dict[str, list[tuple[int, int, list[symbols.Val], list[symbols.Val], list[bool]]]] = {}
        for f, vals in got.values():
            if any(v is not None for v in vals):
                tps = set(_tparams(self.nodes_by_id[f.nid].parent)) if self.nodes_by_id[f.nid].parent is not None \
                    and self.nodes_by_id[f.nid].parent.type == "template_declaration" else set()
                out.setdefault(f.key, []).append((len(f.params), sum(d is not None for d in f.defaults),
                                                  [s.value(d) for d in f.defaults], vals,
                                                  [_takes_string(t, tps) for t in f.ptypes]))
        return out





def _takes_string(ptype: str, tparams: set[str]) -> bool:
    """Whether a parameter declared ``ptype`` may be given a string literal: a
    string or character type, ``auto``, or a template parameter of its function
    (``const std::string &``, ``T``); not ``const ParameterDescriptor &``,
    ``bool``, ``rclcpp::Logger`` (how a call's overload is told apart)."""
    base = ptype.replace("const", "").replace("&", "").replace("*", "").strip()
    return "string" in base.lower() or "char" in base or base in ("auto", "") or base in tparams


def _tparams(decl: Any) -> list[str]:
    """The type parameters' names of a ``template<...>`` declaration."""
    ps = decl.child_by_field_name("parameters")
    return [_T(x.child_by_field_name("name") or (x.named_children[-1] if x.named_children else x))
            for x in (ps.named_children if ps is not None else []) if "type" in x.type]


def scan_cpp(data: bytes, shown: str) -> dict[str, Any]:
    """The record of one C++ file: ``{"nodes": [(name, Src)], "endpoints": [Endpoint],
    "notes": [Note], "classes": {qualified class: {"nodes", "endpoints"}},
    "components": [(qualified class, Src)]}`` and, for the linker (:mod:`link`),
    ``fns``, ``units``, ``calls``, ``fields``, ``consts``, ``node_names``,
    ``member_decls``, ``member_calls``, ``includes``, ``callbacks``, ``ros2``.

    tree-sitter recovers from syntax errors, so a broken file still yields
    what it can; its ERROR regions are reported as one located warning."""
    return _File(data, shown).run()
