"""The scopes of one Python source and the value of a name in them
(docs/ros.md, "Reading real code"): string constants propagated through
assignments, function parameters, ``self.`` attributes and imports.

From the file's :class:`~.pyrecords.PyModule` (either reader):

* a function's parameter is ``("arg", key, i)`` (key ``FILE::Cls.f``; a
  method's ``self`` is not counted), bound where the package calls it;
* a local variable or module constant bound once (``NAME = 'talker'``) is
  its value; bound to two different values it is not read;
* ``self.x`` is ``("field", FILE::Cls, "x")``, bound wherever the class
  assigns it (its constructor usually);
* a name imported from another module (``from pkg.names import TOPIC``,
  ``names.TOPIC``) is ``("ext", "pkg.names.TOPIC")``, found by the linker
  in the package's own modules;
* ``rospy.get_param('~t', 'd')``, rclpy ``declare_parameter``/``get_parameter``
  are parameter reads; ``rospy.get_name()`` is the node's own name;
  ``a + b`` and f-strings are concatenations.

Keys of units (what owns an endpoint): ``FILE::Cls`` for a class,
``FILE::f`` for a module-level function, ``FILE::<module>`` for module code.
"""
from __future__ import annotations

import re
from typing import Any

from rclverify.ros.extract import symbols
from rclverify.ros.extract.pyrecords import PyCall, PyModule, PyVal

#: rclpy/rospy calls whose results are the running graph's names (names found at run time)
DISCOVERY = {"get_topic_names_and_types", "get_service_names_and_types", "get_node_names",
             "get_node_names_and_namespaces", "get_published_topics", "get_topic_type"}

_ROS = ("rospy", "rclpy", "std_msgs", "actionlib", "tf", "tf2_ros", "message_filters", "os", "sys", "math",
        "time", "threading", "numpy", "interactive_markers")
MAX_DEPTH = 10


class PyScope:
    """Scopes of one Python file (see the module docstring)."""

    def __init__(self, mod: PyModule, shown: str) -> None:
        self.mod, self.shown = mod, shown
        self.fns = sorted(mod.functions, key=lambda f: (f[1], -f[2]))
        self.cls = self._class_names()
        self.binds: dict[tuple[str, ...], list[PyVal]] = {}
        self.declared: dict[str, str | None] = {}
        for c in mod.calls:
            if c.func.endswith("declare_parameter") and c.args and c.args[0].kind == "str":
                d = c.args[1] if len(c.args) > 1 else c.kwargs.get("value")
                self.declared.setdefault("~" + c.args[0].text.lstrip("~"),
                                         d.text if d is not None and d.kind == "str" else None)
        for target, v in mod.assigns:
            self.binds.setdefault(self._key(target, v.src.line), []).append(v)

    def _class_names(self) -> list[tuple[str, int, int]]:
        out = []
        for name, a, b in self.mod.classes:
            outer = [c for c in self.mod.classes if c[1] < a and c[2] >= b]
            q = ".".join([c[0] for c in sorted(outer, key=lambda c: c[1])] + [name])
            out.append((q, a, b))
        return out

    # -- where a line is
    def fn_at(self, line: int) -> tuple[str, int, int, list[str], list[PyVal | None]] | None:
        """The innermost function whose lines hold ``line``."""
        inside = [f for f in self.fns if f[1] <= line <= f[2]]
        return min(inside, key=lambda f: f[2] - f[1]) if inside else None

    def class_at(self, line: int) -> str | None:
        """The qualified name of the innermost class whose lines hold ``line``."""
        inside = [c for c in self.cls if c[1] <= line <= c[2]]
        return min(inside, key=lambda c: c[2] - c[1])[0] if inside else None

    def unit_at(self, line: int) -> str:
        """The unit owning code at ``line``: its class, else its module-level function,
        else the module."""
        c = self.class_at(line)
        if c is not None:
            return f"{self.shown}::{c}"
        f = self.fn_at(line)
        if f is not None:
            return f"{self.shown}::{f[0].split('.')[0]}"
        return f"{self.shown}::<module>"

    def fn_key(self, line: int) -> str | None:
        f = self.fn_at(line)
        return f"{self.shown}::{f[0]}" if f is not None else None

    def _key(self, target: str, line: int) -> tuple[str, ...]:
        if target.startswith("self.") and target.count(".") == 1:
            return ("field", self.unit_at(line), target[5:])
        f = self.fn_at(line)
        return ("local", f[0], target) if f is not None else ("module", target)

    # -- values
    def full(self, dotted: str) -> str:
        """A dotted name with its first part replaced by what it was imported as."""
        head, _, rest = dotted.partition(".")
        base = self.mod.imports.get(head, head)
        return f"{base}.{rest}" if rest else base

    def value(self, v: PyVal | None, depth: int = 0) -> symbols.Val:
        """The :mod:`symbols` value of ``v`` in the scope of its own line."""
        if v is None or depth > MAX_DEPTH:
            return None
        if v.kind == "str":
            return symbols.lit(v.text)
        if v.kind == "cat":
            return symbols.cat([self.value(p, depth + 1) for p in v.parts])
        if v.kind == "name":
            return self._name(v.text, v.src.line, depth)
        if v.kind == "other" and re.match(r"(sys\.)?argv\s*\[", v.text):
            return ("runtime", "from argv")
        for c in ([v.call] if v.call else []) + v.calls:
            g = self.getter(c)
            if g is not None:
                return ("param", g[1], g[0], None)
            computed = self.computed_read(c, depth)
            if computed is not None:
                return computed
        if v.call is not None:
            f = self.full(v.call.func)
            if f in ("rospy.get_name", "rospy.names.get_name") or v.call.func.endswith("get_fully_qualified_name"):
                return symbols.NODE
            if v.call.func.rsplit(".", 1)[-1] in DISCOVERY:
                return ("runtime", f"discovered at run time ({v.call.func.rsplit('.', 1)[-1]}())")
            if f == "str" and len(v.call.args) == 1:
                return self.value(v.call.args[0], depth + 1)
            if f == "os.path.join" and v.call.args:
                parts: list[symbols.Val] = []
                for k, a in enumerate(v.call.args):
                    parts += ([symbols.lit("/")] if k else []) + [self.value(a, depth + 1)]
                return symbols.cat(parts)
            callee = self.callee(v.call) if not v.call.kwargs and not v.calls[1:] else None
            if callee is not None:  # a function of the workspace: what it returns, read by the linker
                return ("ret", callee, None, tuple(self.value(a, depth + 1) for a in v.call.args))
        return None

    def computed_read(self, c: PyCall, depth: int) -> symbols.Val:
        """A ROS 2 parameter read whose name is a parameter of the enclosing function
        (a wrapper's ``node.declare_parameter(name, default).value``): ``("param",
        name value, default value or None, None)``, read by the linker; else ``None``."""
        last = c.func.rsplit(".", 1)[-1]
        if last not in ("get_parameter", "declare_parameter", "get_parameter_or") or not c.args or \
                c.args[0].kind == "str":
            return None
        key = self.value(c.args[0], depth + 1)
        if key is None or key[0] != "arg":
            return None
        d = self.value(c.args[1], depth + 1) if last != "get_parameter" and len(c.args) > 1 else None
        return ("param", key, d if d is not None and d[0] in ("str", "arg") else None, None)

    def returns(self) -> dict[str, list[tuple[int, int, list[symbols.Val], list[symbols.Val], list[bool]]]]:
        """Per function key, ``[(parameters, defaulted ones, default values, values
        returned, per parameter whether it may take a string: always)]`` for a function returning a value the linker may read (a
        ``("ret", ...)`` call of it, :mod:`link_returns`)."""
        got: dict[str, list[symbols.Val]] = {}
        for line, pv in self.mod.returns:
            f = self.fn_at(line)
            if f is not None:
                got.setdefault(f[0], []).append(self.value(pv))
        out = {}
        for f in self.fns:
            vals = got.get(f[0], [])
            if any(x is not None for x in vals):
                out[f"{self.shown}::{f[0]}"] = [(len(f[3]), sum(d is not None for d in f[4]),
                                                 [self.value(d) if d is not None else None for d in f[4]], vals,
                                                 [True] * len(f[3]))]
        return out

    def _name(self, name: str, line: int, depth: int) -> symbols.Val:
        f = self.fn_at(line)
        if name.startswith("self.") and name.count(".") == 1:
            return ("field", self.unit_at(line), name[5:])
        if f is not None and name in f[3]:
            return ("arg", f"{self.shown}::{f[0]}", f[3].index(name))
        for key in ([("local", f[0], name)] if f is not None else []) + [("module", name)]:
            if key in self.binds:
                return self._one(self.binds[key], depth)
        head = name.split(".")[0]
        parsed = self._argparse(head, name.partition(".")[2], f)
        if parsed is not None:
            return parsed
        if head in self.mod.imports:
            origin = self.full(name)
            if origin.split(".")[0] in _ROS and not any(f".{k}." in origin for k in ("msg", "srv", "action")):
                return None  # an interface class (std_msgs.msg.String) is a type a helper may be given
            return ("ext", origin)
        return None

    def _argparse(self, head: str, attr: str, f: tuple[Any, ...] | None) -> symbols.Val:
        """``("runtime", "from argparse option --topic")`` for ``args.topic`` where ``args``
        is bound to an ``ArgumentParser``'s ``parse_args()`` / ``parse_known_args()``
        (Python docs, argparse: an option's ``dest`` is its long name, ``-`` as ``_``)."""
        if not attr or "." in attr:
            return None
        keys = ([("local", f[0], head)] if f is not None else []) + [("module", head)]
        vals = [v for k in keys for v in self.binds.get(k, [])]
        if not vals or not all(v.call is not None and v.call.func.rsplit(".", 1)[-1] in (
                "parse_args", "parse_known_args") for v in vals):
            return None
        opts = [c.args[i].text for c in self.mod.calls if c.func.endswith(".add_argument")
                for i in range(len(c.args)) if c.args[i].kind == "str"
                and c.args[i].text.lstrip("-").replace("-", "_") == attr]
        opt = opts[-1] if opts else attr
        return ("runtime", f"from argparse {'option' if opt.startswith('-') else 'argument'} {opt}")

    def _one(self, vals: list[PyVal], depth: int) -> symbols.Val:
        got = {self.value(x, depth + 1) for x in vals}
        return next(iter(got)) if len(got) == 1 else None

    def getter(self, c: PyCall) -> tuple[str | None, str] | None:
        """``(default, parameter)`` when call ``c`` reads a ROS parameter (``rospy.get_param``;
        rclpy ``get_parameter``/``declare_parameter``: the node's ``~name``)."""
        f = self.full(c.func) if c.func else ""
        if not c.args or c.args[0].kind != "str":
            return None
        name = c.args[0].text
        if f in ("rospy.get_param", "rospy.client.get_param"):
            d = c.args[1] if len(c.args) > 1 else c.kwargs.get("default")
            return (d.text if d is not None and d.kind == "str" else None), name
        last = c.func.rsplit(".", 1)[-1]
        if last in ("get_parameter", "declare_parameter", "get_parameter_or"):
            p = "~" + name.lstrip("~")
            d = c.args[1] if last != "get_parameter" and len(c.args) > 1 else None
            return (d.text if d is not None and d.kind == "str" else self.declared.get(p)), p
        return None

    def fields(self) -> dict[tuple[str, str], list[symbols.Val]]:
        """``{(unit, attribute): [value, ...]}`` of every ``self.x = ...`` of the file."""
        return {(k[1], k[2]): [self.value(v) for v in vs] for k, vs in self.binds.items() if k[0] == "field"}

    def consts(self) -> dict[str, symbols.Val]:
        """``{name: value}`` of the module's constants (bound once, at module level)."""
        out = {}
        for k, vs in self.binds.items():
            if k[0] == "module":
                v = self._one(vs, 0)
                if v is not None:
                    out[k[1]] = v
        return out

    def callee(self, c: PyCall) -> str | None:
        """The key of what call ``c`` calls: ``FILE::Cls.f`` for ``self.f(...)``,
        ``FILE::Name`` for a class or function of this file, ``ext:pkg.mod.Name``
        for an imported one; ``None`` for ROS, standard or unknown callees."""
        f = c.func
        if not f or f.startswith(("super()", ".")):
            return None
        if f.startswith("self.") and f.count(".") == 1:
            cls = self.class_at(c.src.line)
            return f"{self.shown}::{cls}.{f[5:]}" if cls else None
        head = f.split(".")[0]
        if "." not in f and (any(q == f for q, _a, _b in self.cls) or any(fn[0] == f for fn in self.fns)):
            return f"{self.shown}::{f}"
        if head in self.mod.imports:
            origin = self.full(f)
            return None if origin.split(".")[0] in _ROS else f"ext:{origin}"
        return None
