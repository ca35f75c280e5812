"""The scopes of one C++ file and the value of a name expression in them
(docs/ros.md, "Reading real code").

Indexed once per file from tree-sitter's syntax tree:

* each function definition: its key (``ns::C::f``; a constructor is
  ``ns::C::C``), its unit (the class it belongs to, or the function itself),
  its parameters with their types and default arguments;
* each class body: members and their types, base classes; static members and
  namespace-scope constants initialised with a string, ``#define NAME "x"``;
* each function's local variables: what they are initialised or assigned
  with (an expression, a ``ros::NodeHandle``'s constructor arguments, a
  parameter read by reference).

The value of an expression in these scopes is :mod:`cpp_values`' job; the
names the syntax writes (a callee, a declarator, the enclosing namespaces and
classes) are read by :mod:`cpp_names`.
Local variables are scoped by function; members by class.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import symbols, treesitter
from rclverify.ros.extract.cpp_names import base_name, declarator_name, namespaces_of, untemplated
from rclverify.ros.extract.cpp_params import param_read

_HANDLE_TYPES = ("NodeHandle",)
#: what changes a string variable in place: C writers (their first argument) and std::string methods
_C_WRITERS = {"sprintf", "snprintf", "strcpy", "strncpy", "strcat", "strncat", "memcpy", "sscanf", "vsnprintf"}
_MUTATORS = {"append", "insert", "replace", "assign", "push_back", "erase", "resize", "clear", "pop_back"}
UNKNOWN = ("unknown",)  # a binding whose value is not read statically
_T = treesitter.text
MAX_DEPTH = 12


class Fn:
    """A function definition: ``key``, ``unit``, parameter ``params`` (names),
    ``ptypes`` (type texts) and ``defaults`` (default-argument nodes or ``None``)."""

    def __init__(self, key: str, unit: str, in_class: bool, nid: int) -> None:
        self.key, self.unit, self.in_class, self.nid = key, unit, in_class, nid
        self.params: list[str] = []
        self.ptypes: list[str] = []
        self.pconst: list[bool] = []  # per parameter: declared const
        self.defaults: list[Any] = []


class CppScope:
    """Scopes and values of one file (see the module docstring)."""

    def __init__(self, nodes: list[Any]) -> None:
        self.fns: dict[int, Fn] = {}
        self.decls: dict[str, Fn] = {}  # methods declared in a class body, by key
        self.classes: dict[str, dict[str, Any]] = {}
        self.consts: dict[str, list[Any]] = {}
        self.locals: dict[tuple[int, str], list[Any]] = {}
        self.ltypes: dict[tuple[int, str], str] = {}
        self.fields: dict[tuple[str, str], list[Any]] = {}  # (class, member) -> [(fn id, value node) | Val]
        self.using_ns: list[str] = []
        self.declared: dict[str, str | None] = {}  # ROS 2 parameter -> its declared default
        self._fn_of: dict[int, Fn | None] = {}
        self.override: Fn | None = None
        for n in nodes:
            t = n.type
            if t == "function_definition":
                self._function(n)
            elif t in ("class_specifier", "struct_specifier") and n.child_by_field_name("body") is not None:
                self._class(n)
            elif t == "preproc_def" and n.child_by_field_name("value") is not None:
                v = _T(n.child_by_field_name("value")).strip()
                if len(v) >= 2 and v[0] == v[-1] == '"' and "\\" not in v and '"' not in v[1:-1]:
                    self.consts.setdefault(_T(n.child_by_field_name("name")), []).append(symbols.lit(v[1:-1]))
            elif t == "using_declaration" and any(c.type == "namespace" for c in n.children):
                self.using_ns.append(_T(n.named_children[-1]) if n.named_children else "")
        calls: list[Any] = []
        for n in nodes:
            if n.type == "declaration":
                self._declaration(n)
            elif n.type == "for_range_loop":  # for (auto & s : sources): s is each element
                nm, fn = declarator_name(n.child_by_field_name("declarator")), self.fn_of(n)
                d = n.child_by_field_name("declarator")
                while d is not None and d.type in ("reference_declarator", "pointer_declarator"):
                    d = next((c for c in d.named_children if c.type == "structured_binding_declarator"), None) \
                        or d.child_by_field_name("declarator")
                nm = d if d is not None and d.type == "structured_binding_declarator" else nm
                if nm is not None and nm.type == "structured_binding_declarator" and fn is not None \
                        and n.child_by_field_name("right") is not None:  # for (auto & [key, topic] : topics)
                    for i, part in enumerate(c for c in nm.named_children if c.type == "identifier"):
                        self.locals.setdefault((fn.nid, _T(part)), []).append(
                            ("each", n.child_by_field_name("right"), i))
                elif nm is not None and fn is not None and n.child_by_field_name("right") is not None:
                    self.ltypes[(fn.nid, _T(nm))] = _T(n.child_by_field_name("type"))
                    self.locals.setdefault((fn.nid, _T(nm)), []).append(("each", n.child_by_field_name("right")))
            elif n.type == "assignment_expression" and n.child_by_field_name("operator") is not None:
                op = _T(n.child_by_field_name("operator"))
                self._assign(n.child_by_field_name("left"), n.child_by_field_name("right") if op == "=" else None, n)
            elif n.type == "field_initializer":
                fn = self.fn_of(n)
                head = n.named_children[0] if n.named_children else None
                a = next((c for c in n.children if c.type in ("argument_list", "initializer_list")), None)
                if fn is not None and head is not None and a is not None and fn.in_class:
                    self.fields.setdefault((fn.unit, _T(head)), []).append((fn, ("init", list(a.named_children), _T(head))))
            elif n.type == "call_expression":
                calls.append(n)
                r = param_read(n)
                if r is not None and r[4] and "declare_parameter" in _T(n.child_by_field_name("function")):
                    self.declared.setdefault(r[0], r[1])
                if r is not None and r[2] is not None:
                    self._bind(r[2], ("read", n), n)
                f = n.child_by_field_name("function")
                self._mutation(n, f)
                if f is not None and f.type == "field_expression" and _T(f.child_by_field_name("field")) == \
                        "arguments" and n.child_by_field_name("arguments") is not None and any(
                        a.type == "initializer_list" for a in n.child_by_field_name("arguments").named_children):
                    self._bind(f.child_by_field_name("argument"), n, n)  # options.arguments({"name"}): set in place
                if f is not None and f.type == "field_expression" and f.child_by_field_name("field") is not None \
                        and f.child_by_field_name("field").type == "template_method" \
                        and _T(f.child_by_field_name("field").child_by_field_name("name")) == "init":
                    self._bind(f.child_by_field_name("argument"), ("ops", n), n)

        for n in calls:
            self._out_args(n)

    # -- indexing
    def _out_args(self, n: Any) -> None:
        """``getParameters(topic)`` where this file's ``getParameters(std::string & t)``
        reads a parameter into ``t``: the caller's local ``topic`` holds what ``t`` is
        given (an out-parameter)."""
        f = n.child_by_field_name("function")
        a = n.child_by_field_name("arguments")
        fn = self.fn_of(n)
        if f is None or a is None or fn is None or not a.named_children:
            return
        if f.type == "field_expression":
            if _T(f.child_by_field_name("argument")) != "this":
                return
            f = f.child_by_field_name("field")
        if f is None or f.type != "identifier" and f.type != "field_identifier":
            return
        name = _T(f)
        keys = {f"{fn.unit}::{name}", name} if fn.in_class else {name}
        callee = next((c for c in self.fns.values() if c.key in keys and c.nid != fn.nid), None)
        if callee is None:
            return
        for i, x in enumerate(a.named_children[:len(callee.params)]):
            ty = callee.ptypes[i]
            if x.type == "identifier" and (fn.nid, _T(x)) in self.ltypes and ty.endswith("&") and \
                    not callee.pconst[i] and self.locals.get((callee.nid, callee.params[i])):
                self.locals.setdefault((fn.nid, _T(x)), []).append(("out", callee, callee.params[i]))

    def _function(self, n: Any) -> None:
        fd = n.child_by_field_name("declarator")
        while fd is not None and fd.type != "function_declarator":
            fd = fd.child_by_field_name("declarator")
        if fd is None:
            return
        name = untemplated(_T(fd.child_by_field_name("declarator")).replace(" ", ""))
        nss, cls = namespaces_of(n)
        pre = "::".join(nss + cls)
        key = f"{pre}::{name}" if pre else name
        if cls:
            unit = pre
        elif "::" in name:
            unit = key.rsplit("::", 1)[0]
        else:
            unit = key
        if unit.split("::")[-1] == name.split("::")[-1] and (cls or "::" in name):
            key = f"{unit}::{unit.split('::')[-1]}"  # a constructor
        fn = Fn(key, unit, bool(cls) or "::" in name, n.id)
        params = fd.child_by_field_name("parameters")
        for p in params.named_children if params is not None else []:
            if p.type not in ("parameter_declaration", "optional_parameter_declaration"):
                continue
            d = declarator_name(p.child_by_field_name("declarator"))
            fn.params.append(_T(d) if d is not None else "")
            fn.ptypes.append(_T(p.child_by_field_name("type")) + (
                " &" if "&" in _T(p.child_by_field_name("declarator") or p) else ""))
            fn.pconst.append(any(c.type == "type_qualifier" and _T(c) == "const" for c in p.children))
            fn.defaults.append(p.child_by_field_name("default_value"))
        if key.endswith("::" + unit.split("::")[-1]) and any(f.key == key and len(f.params) != len(fn.params)
                                                                 for f in self.fns.values()):
            # a constructor overload: keyed by its arity, the linker runs only the one called
            fn.key = f"{key}#{len(fn.params)}"
        self.fns[n.id] = fn

    def _class(self, n: Any) -> None:
        nss, cls = namespaces_of(n)
        name = "::".join(nss + cls + [_T(n.child_by_field_name("name")).split("<")[0]])
        info = self.classes.setdefault(name, {"members": {}, "bases": []})
        tpl = n.parent.child_by_field_name("parameters") if n.parent is not None and \
            n.parent.type == "template_declaration" else None
        if tpl is not None:  # template<typename ServiceT> class Caller: read where it is made
            info["tparams"] = [_T(x.child_by_field_name("name") or next(
                (c for c in x.named_children if c.type == "type_identifier"), x)) for x in tpl.named_children]
        for c in n.children:
            if c.type == "base_class_clause":
                info["bases"].extend(_T(b) for b in c.named_children if b.type != "access_specifier")
        for f in n.child_by_field_name("body").named_children:
            if f.type == "declaration" or f.type == "field_declaration" and any(
                    d.type == "function_declarator" for d in f.children_by_field_name("declarator")):
                self._method_decl(f, name)
                continue
            if f.type != "field_declaration":
                continue
            ty = _T(f.child_by_field_name("type"))
            dv = f.child_by_field_name("default_value")
            for d in f.children_by_field_name("declarator"):
                if d.type == "function_declarator":
                    continue
                nm = declarator_name(d)
                if nm is None:
                    continue
                info["members"][_T(nm)] = ty
                if d.type == "reference_declarator":  # Costmap & costmap_: bound in a constructor, never made
                    info.setdefault("refs", []).append(_T(nm))
                if dv is not None:
                    v = dv.named_children[0] if dv.type == "initializer_list" and len(dv.named_children) == 1 else dv
                    self.fields.setdefault((name, _T(nm)), []).append((None, v))
                    if any(c.type in ("storage_class_specifier",) and _T(c) == "static" for c in f.children):
                        self.consts.setdefault(_T(nm), []).append(v)
                        self.consts.setdefault(f"{name.split('::')[-1]}::{_T(nm)}", []).append(v)

    def _method_decl(self, f: Any, cls: str) -> None:
        """A method or constructor declared (not defined) in class ``cls``: its
        parameters and default arguments (often only the header has them)."""
        fd = next((d for d in f.children_by_field_name("declarator") if d.type == "function_declarator"), None)
        if fd is None:
            return
        name = _T(fd.child_by_field_name("declarator")).split("<")[0]
        last = cls.split("::")[-1]
        key = f"{cls}::{last}" if name == last else f"{cls}::{name}"
        fn = Fn(key, cls, True, -1)
        params = fd.child_by_field_name("parameters")
        for p in params.named_children if params is not None else []:
            if p.type in ("parameter_declaration", "optional_parameter_declaration"):
                d = declarator_name(p.child_by_field_name("declarator"))
                fn.params.append(_T(d) if d is not None else "")
                fn.ptypes.append(_T(p.child_by_field_name("type")))
                fn.defaults.append(p.child_by_field_name("default_value"))
        self.decls[key] = fn

    def _declaration(self, n: Any) -> None:
        fn = self.fn_of(n)
        ty = _T(n.child_by_field_name("type"))
        for d in n.children_by_field_name("declarator"):
            nm = declarator_name(d)
            if nm is None or nm.type not in ("identifier", "field_identifier"):
                continue
            v = d.child_by_field_name("value") if d.type == "init_declarator" else None
            if fn is None:
                if v is not None:
                    self.consts.setdefault(_T(nm), []).append(v)
                continue
            key = (fn.nid, _T(nm))
            self.ltypes[key] = ty
            if base_name(ty) in _HANDLE_TYPES and (v is None or v.type in ("argument_list", "initializer_list")):
                self.locals.setdefault(key, []).append(("nhargs", list(v.named_children) if v is not None else []))
            elif v is not None and v.type not in ("argument_list", "initializer_list"):
                self.locals.setdefault(key, []).append(v)
            elif v is not None and len(v.named_children) == 1 and v.named_children[0].type != "initializer_list":
                self.locals.setdefault(key, []).append(v.named_children[0])
            elif v is not None and v.type == "initializer_list" or v is not None and len(v.named_children) == 1:
                self.locals.setdefault(key, []).append(("elems", v))  # a container of literals, iterated
            else:
                self.locals.setdefault(key, [])

    def _assign(self, left: Any, right: Any, at: Any) -> None:
        """``left = right``; ``right`` is ``None`` for a compound assignment (``+=``): a value
        no longer known statically."""
        if left is not None:
            self._bind(left, right if right is not None else UNKNOWN, at)

    def _mutation(self, n: Any, f: Any) -> None:
        """A call that changes a string in place (``snprintf(buf, ...)``, ``strcat``,
        ``topic.append(...)``): its variable no longer holds what it was initialised with."""
        if f is None:
            return
        a = n.child_by_field_name("arguments")
        if f.type == "field_expression" and _T(f.child_by_field_name("field")) in _MUTATORS:
            self._bind(f.child_by_field_name("argument"), UNKNOWN, n)
        elif _T(f).split("::")[-1] in _C_WRITERS and a is not None and a.named_children:
            self._bind(a.named_children[0], UNKNOWN, n)

    def _bind(self, target: Any, what: Any, at: Any) -> None:
        fn = self.fn_of(at)
        name, member = self._target(target, fn)
        if name is None or fn is None:
            return
        if member:
            self.fields.setdefault((fn.unit, name), []).append((fn, what))
        else:
            self.locals.setdefault((fn.nid, name), []).append(what)

    def _target(self, t: Any, fn: Fn | None) -> tuple[str | None, bool]:
        if t.type == "field_expression" and _T(t.child_by_field_name("argument")) == "this":
            return _T(t.child_by_field_name("field")), True
        if t.type == "pointer_expression" and t.named_children:
            return self._target(t.named_children[-1], fn)
        if t.type != "identifier" or fn is None:
            return None, False
        name = _T(t)
        local = (fn.nid, name) in self.ltypes or name in fn.params
        return name, not local and fn.in_class

    # -- lookups
    def fn_of(self, n: Any) -> Fn | None:
        """The function definition ``n`` lies in (``None`` at namespace scope); while
        :attr:`override` is set, that function (for expressions re-read out of place)."""
        if self.override is not None:
            return self.override
        p = n.parent
        chain = []
        while p is not None:
            if p.id in self._fn_of:
                found = self._fn_of[p.id]
                break
            chain.append(p.id)
            if p.type == "function_definition" and p.id in self.fns:
                found = self.fns[p.id]
                break
            p = p.parent
        else:
            found = None
        for i in chain:
            self._fn_of[i] = found
        return found

    def type_of(self, n: Any) -> str | None:
        """The declared type text of variable, parameter or member expression ``n``."""
        fn = self.fn_of(n)
        if n.type == "field_expression" and _T(n.child_by_field_name("argument")) == "this":
            n = n.child_by_field_name("field")
        elif n.type == "pointer_expression" and n.named_children:
            n = n.named_children[-1]
        name = _T(n)
        if fn is not None:
            if (fn.nid, name) in self.ltypes:
                return self.ltypes[(fn.nid, name)]
            if name in fn.params:
                return fn.ptypes[fn.params.index(name)]
            got: str | None = self.classes.get(fn.unit, {}).get("members", {}).get(name)
            return got
        return None
