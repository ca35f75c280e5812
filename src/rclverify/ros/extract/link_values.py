"""The values of a linked program's symbolic names (:mod:`symbols`): what each
function parameter is given at each call site, what each member is bound to,
what an imported constant is (docs/ros.md, "Reading real code").

:class:`Values` is the evaluation half of :class:`~.link.Linker` (which
provides the program's tables: ``fns``, ``sites``, ``units``, ``fields``,
``recs``, ``code``, ``runs`` and ``match``).  A value is evaluated *in a
function called with an environment* (parameter index -> concrete value);
a function's environments are those of its call sites, each evaluated in
its caller's environments (:data:`MAX_DEPTH` deep, :data:`MAX_VALUES` at
most); the parts of one value that read one function's parameters are read
together, call site by call site.  Work is bounded; a value nobody can read
is ``None``.
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import symbols
from rclverify.ros.extract.cpp_names import is_node_type
from rclverify.ros.extract.link_units import UnitInfo, unit_of

MAX_DEPTH = 8
#: a member declared with an interface spec: component_interface_utils::Publisher<ns::Spec>::SharedPtr
_SPEC_MEMBER = re.compile(r"(?:^|::)(?:Publisher|Subscription|Service|Client)<([A-Za-z_:][\w:]*)>")
MAX_VALUES = 32


def limit(xs: list[Any]) -> list[Any]:
    """``xs`` without repeats, at most :data:`MAX_VALUES` of them."""
    out: list[Any] = []
    for x in xs:
        if x not in out:
            out.append(x)
            if len(out) >= MAX_VALUES:
                break
    return out


class Values:
    """The evaluation of symbolic values over a linked program (mixed into the linker)."""

    fns: dict[str, tuple[str, list[str], list[str], list[Any]]]
    sites: dict[str, list[tuple[list[Any], dict[str, Any], str | None]]]
    units: dict[str, UnitInfo]
    fields: dict[tuple[str, str], list[Any]]
    recs: dict[str, dict[str, Any]]
    code: Any
    _memo: dict[str, list[dict[int, Any]]]
    _stack: set[str]
    pins: dict[str, int]  # function key -> the one call site whose arguments are read

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def runs(self, unit: str | None, fkey: str | None, reach: set[str] | None = None) -> bool:
            ...

        def match(self, name: str, caller: str | None) -> str | None:
            ...

        def returned(self, v: Any, env: dict[int, Any], fkey: str | None, depth: int) -> list[Any]:
            ...

    def remapped(self, opts: Any, ns: Any, env: dict[int, Any], fkey: str | None) -> tuple[str | None, str | None,
                                                                                           bool]:
        """``(name, namespace, ns is options)``: the node name and namespace the remap
        rules of the ``NodeOptions`` a node is made with give (``-r __node:=n``,
        ``__ns:=/x``; rcl applies them over the code's name), ``None`` where they
        give none; the third is true when the value read as the namespace is
        those options (``Node(name, options)``)."""
        got = [x for x in (self.eval(opts, env, fkey) if opts is not None else []) if x is not None and x[0] == "opts"]
        nsv = [x for x in (self.eval(ns, env, fkey) if ns is not None else []) if x is not None and x[0] == "opts"]
        rules = [symbols.node_remaps(x) for x in got + nsv]
        name = next((r[0] for r in rules if r[0]), None)
        space = next((r[1] for r in rules if r[1]), None)
        return name, space, bool(nsv) or (ns is not None and ns == opts)

    def contexts(self, fkey: str | None, depth: int = 0) -> list[dict[int, Any]]:
        """The parameter values each call site of ``fkey`` gives (``[{}]``: none known)."""
        if fkey is None or fkey not in self.fns:
            return [{}]
        if fkey in self._memo:
            return self._memo[fkey]
        if depth > MAX_DEPTH or fkey in self._stack:
            return [{}]
        self._stack.add(fkey)
        params = self.fns[fkey][1]
        envs: list[dict[int, Any]] = []
        sites = self.sites.get(fkey, [])
        for args, kwargs, caller in sites[self.pins[fkey]:self.pins[fkey] + 1] if fkey in self.pins else sites:
            if caller is not None and not self.runs(None, caller):
                continue
            for cenv in self.contexts(caller, depth + 1):
                partial: list[dict[int, Any]] = [{}]
                pairs = list(enumerate(args)) + [(params.index(k), v) for k, v in kwargs.items() if k in params]
                for i, a in pairs:
                    vals = self.eval(a, cenv, caller, depth + 1)
                    partial = limit([{**e, i: v} for e in partial for v in vals])
                envs.extend(partial)
        self._stack.discard(fkey)
        out = limit(envs) or [{}]
        self._memo[fkey] = out
        return out

    def eval(self, v: Any, env: dict[int, Any], fkey: str | None, depth: int = 0) -> list[Any]:
        """Every concrete value ``v`` takes in function ``fkey`` called with ``env``."""
        if v is None or depth > MAX_DEPTH:
            return [None]
        k = v[0]
        if k in ("str", "node", "each", "runtime"):
            return [v]
        if k == "any":  # a range-for over literals: each element
            return limit([y for x in v[1] for y in self.eval(x, env, fkey, depth + 1)])
        if k == "opts":  # NodeOptions' arguments, each read
            items: list[tuple[Any, ...]] = [()]
            for x in v[1]:
                items = limit([p + (y,) for p in items for y in self.eval(x, env, fkey, depth + 1)])
            return [("opts", p) for p in items]
        if k == "optarg":  # options.arguments()[i]
            return limit([y[1][v[2]] if y is not None and y[0] == "opts" and v[2] < len(y[1]) else None
                          for y in self.eval(v[1], env, fkey, depth + 1)])
        homes = {h for h in _homes(v) if h != fkey and h in self.fns}
        if len(homes) == 1 and k != "arg":
            # the parts of one function's parameters are read together, call site by call site
            home = homes.pop()
            joint: list[Any] = []
            for e in self.contexts(home, depth + 1):
                joint += self.eval(v, e, home, depth + 1)
            return limit(joint)
        if k == "arg":
            if v[1] == fkey and v[2] in env:
                return [env[v[2]]]
            if v[1] == fkey or v[1] not in self.fns:
                return self._default(v[1], v[2], depth)
            out: list[Any] = []
            for e in self.contexts(v[1], depth + 1):
                out += self.eval(v, e, v[1], depth + 1) if v[2] in e else self._default(v[1], v[2], depth)
            return limit(out)
        if k == "field":
            return self._field(v[1], v[2], depth)
        if k == "specof":  # a member declared Publisher<ns::Spec>::SharedPtr: that spec's name
            spec = self.spec_of(v[1], v[2])
            return self.eval(("spec", spec), env, fkey, depth + 1) if spec else [None]
        if k == "spec":  # an interface spec's static name[] (ns::Spec), as the program's class declares it
            units = [u for u, m in self.fields if m == "name" and (u == v[1] or u.endswith("::" + v[1]))]
            return limit([x for b in self.fields[(units[0], "name")] for x in self.eval(b, {}, None, depth + 1)]) \
                if len(units) == 1 else [None]
        if k == "ext":
            hit = self.code.module(v[1])
            rec = self.code.records.get(hit[0], {}) if hit else {}
            c = rec.get("consts", {}).get(hit[1]) if hit else None
            if c is None and hit is None and isinstance(v[1], str) and (".msg." in v[1] or ".srv." in v[1]
                                                                        or ".action." in v[1]):
                return [v]  # an interface class (std_srvs.srv.Trigger): a type a helper is given
            return self.eval(c, {}, None, depth + 1) if c is not None else [None]
        if k == "param":
            keys = [v[1]] if isinstance(v[1], str) else [
                "~" + t if t is not None and not t.startswith("~") else None
                for t in (symbols.text(x) for x in self.eval(v[1], env, fkey, depth + 1))]  # a computed key
            defaults = [v[2]] if not isinstance(v[2], tuple) else [  # a wrapper's default: its argument
                symbols.text(x) for x in self.eval(v[2], env, fkey, depth + 1)]
            return limit([("param", key, d, h) if key is not None else None for key in keys for d in defaults
                          for h in (self.eval(v[3], env, fkey, depth + 1) if v[3] else [None])])
        if k == "ret":
            return self.returned(v, env, fkey, depth)
        if k == "nh":
            segs: list[tuple[Any, ...]] = [()]
            for kind, x in v[1]:
                xs = self.eval(x, env, fkey, depth + 1) if x is not None else [None]
                if kind == "h":
                    xs = [y if y is not None and y[0] == "nh" else None for y in xs]
                segs = limit([s + ((kind, y),) for s in segs for y in xs])
            return [("nh", s) for s in segs]
        if k == "cat":
            parts: list[list[Any]] = [[]]
            for x in v[1]:
                parts = limit([p + [y] for p in parts for y in self.eval(x, env, fkey, depth + 1)])
            return limit([symbols.cat(p) for p in parts])
        if k == "info":  # image_transport's camera_info beside an image topic read here
            return limit([symbols.camera_info(x) if x is not None and symbols.is_concrete(x) else None
                          for x in self.eval(v[1], env, fkey, depth + 1)])
        if k == "ops":
            return [("ops", v[1], n, v[3], v[4]) for n in self.eval(v[2], env, fkey, depth + 1)]
        return [None]

    def _default(self, fkey: str, i: int, depth: int) -> list[Any]:
        f = self.fns.get(fkey)
        d = f[3][i] if f is not None and i < len(f[3]) else None
        return self.eval(d, {}, fkey, depth + 1) if d is not None else [None]

    def spec_of(self, unit: str, member: str) -> str | None:
        """The interface spec a member of class ``unit`` (or of a base of it) is
        declared with: ``ns::Spec`` of ``component_interface_utils::Publisher<ns::Spec>::SharedPtr``
        (also ``Subscription``, ``Service``, ``Client``); ``None`` otherwise."""
        for u in [unit] + [b for b in (self.match(x, unit) for x in unit_of(self.units, unit).bases) if b]:
            ty = unit_of(self.units, u).members.get(member)
            m = _SPEC_MEMBER.search(ty.replace(" ", "")) if ty else None
            if m is not None:
                return m.group(1).lstrip(":")
        return None

    def _field(self, unit: str, name: str, depth: int) -> list[Any]:
        ty, binds = None, None
        for u in [unit] + [b for b in (self.match(x, unit) for x in unit_of(self.units, unit).bases) if b]:
            ty = ty or unit_of(self.units, u).members.get(name)
            binds = binds or self.fields.get((u, name))
        handle = ty is not None and is_node_type(ty)
        if not binds:
            if handle:
                return [("nh", ())]
            consts = [r.get("consts", {}).get(name) for r in self.recs.values()]
            got = {c for c in consts if c is not None}
            return self.eval(next(iter(got)), {}, None, depth + 1) if len(got) == 1 else [None]
        out: list[Any] = []
        for b in binds:
            for x in self.eval(b, {}, None, depth + 1):
                if handle and x is not None and x[0] != "nh":
                    x = ("nh", (("ns", x),))
                out.append(x)
        return limit(out)


def _homes(v: Any) -> set[str]:
    """The functions whose parameters value ``v`` reads (directly, in a concatenation,
    a handle or a parameter read)."""
    if v is None or not isinstance(v, tuple) or not v:
        return set()
    if v[0] == "arg":
        return {v[1]}
    if v[0] == "cat":
        return set().union(*(_homes(x) for x in v[1]))
    if v[0] == "nh":
        return set().union(*(_homes(x) for _k, x in v[1]))
    if v[0] == "param":
        return _homes(v[3]) | (_homes(v[1]) if isinstance(v[1], tuple) else set()) | \
            (_homes(v[2]) if isinstance(v[2], tuple) else set())
    if v[0] == "ret":
        return set().union(*(_homes(x) for x in v[3]))
    if v[0] == "ops":
        return _homes(v[2])
    if v[0] == "info":
        return _homes(v[1])
    if v[0] in ("opts", "any"):
        return set().union(*(_homes(x) for x in v[1]))
    if v[0] == "optarg":
        return _homes(v[1])
    return set()
