"""The linker: one program's endpoints and node names, read across all the
files it runs (docs/ros.md, "Reading real code").

From the program's entry units (:mod:`programs`) the linker follows what
they construct and call (C++ ``Sensor s(nh, "scan")``, a member initialised
in a constructor, ``new``/``make_shared``, a default-constructed member, a
base class; Python ``Sensor(self, 'scan')``, ``self.start('x')``, an
imported class or function) to every class and function the program runs.
Endpoints created there belong to the program; names that their file left
symbolic (:mod:`symbols`) are evaluated here:

* a parameter of a function or constructor takes the value each call site
  passes (its default argument when the site passes none): one endpoint per
  distinct name, each at the creating call's line;
* a member takes what the class's constructor (or any method) binds to it,
  a node handle member the node's own handle when nothing binds it;
* an imported Python constant is looked up in the package module that
  defines it;
* a node handle's namespaces are those of the handle each call site passes.

Helper objects held as members (``tf2_ros::TransformBroadcaster br_;``, an
actionlib server initialised in a constructor, a ``message_filters``
subscriber whose ``subscribe`` is called) get their class from the
program's declarations.  When the program names several nodes, each
endpoint belongs to the node whose class creates it or constructs (directly
or not) the class that does; the rest to the node named outside any class.
Values are evaluated by :mod:`link_values` (bounded: :data:`MAX_DEPTH` nested
calls, :data:`MAX_VALUES` values).

Long module: the walk over what a program runs and the evaluation of the
names it leaves symbolic share one index of the program (classes, aliases,
overloads, members by name), built once per program; the value evaluation
itself is already apart (:mod:`link_values`, :mod:`link_members`,
:mod:`link_types`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any, Callable

from rclverify.ros.extract import emit, names, plugins, symbols
from rclverify.ros.extract.cpp_types import alias_index, alias_of, split_template
from rclverify.ros.extract.model import Endpoint, Note, Src
from rclverify.ros.extract.link_members import LinkMembers
from rclverify.ros.extract.link_returns import Returns
from rclverify.ros.extract.link_types import Instances, is_template_param
from rclverify.ros.extract.link_values import MAX_DEPTH, MAX_VALUES, Values, _homes
from rclverify.ros.extract.programs import PackageCode, Program
from rclverify.ros.extract.unit_names import canonical

__all__ = ["Linked", "Linker", "MAX_DEPTH", "MAX_VALUES"]
_IDENT = re.compile(r"[A-Za-z_][\w:]*")


@dataclass
class Linked:
    """A linked program: ``nodes`` ``[(name, where named, namespace or None)]`` (``kinds``:
    each one's kind, ``"lifecycle"`` for a managed node, else ``None``), ``endpoints`` ``[(Endpoint, index of its node in nodes, or -1)]``, ``notes``
    and the ``files`` that gave any of them."""

    nodes: list[tuple[str, Src, str | None]] = field(default_factory=list)
    kinds: list[str | None] = field(default_factory=list)  # per node: "lifecycle" or None
    endpoints: list[tuple[Endpoint, int]] = field(default_factory=list)
    notes: list[Note] = field(default_factory=list)
    files: list[str] = field(default_factory=list)


#: why an endpoint of a class nothing constructs is not in the graph (docs/ros.md)
UNBUILT = ("nothing this program runs is read to construct the class (a construction through a container's "
           "emplace_back/push_back or a factory the scan does not follow is not read): not in the graph")


class Linker(LinkMembers, Values, Returns, Instances):
    """Link one program of a package (see the module docstring); ``known(t)`` says
    whether the scan's type table defines message type ``t``."""

    def __init__(self, prog: Program, code: PackageCode, known: Callable[[str], bool]) -> None:
        self.prog, self.code, self.known = prog, code, known
        self.recs = canonical({f: code.records[f] for f in prog.files if f in code.records})
        self.fns: dict[str, tuple[str, list[str], list[str], list[Any]]] = {}
        self.units: dict[str, dict[str, Any]] = {}
        self.fields: dict[tuple[str, str], list[Any]] = {}
        self.callbacks: dict[str, str] = {}
        self.aliases: dict[str, str] = {}
        self.calls: list[tuple[Any, ...]] = []
        self.using_ns = sorted({ns for r in self.recs.values() for ns in r.get("using_ns", [])})
        self.optional: dict[str, int] = {k: n for r in self.recs.values() for k, n in r.get("optional", {}).items()}
        self.returns: dict[str, list[Any]] = {}
        self.reading: set[tuple[str, int]] = set()
        self.fn_tparams: dict[str, list[str]] = {}
        self.call_targs: list[tuple[str, str | None, str | None, int, list[str]]] = []
        entry_units = self._merge_records(prog)
        self.alias_index = alias_index(self.aliases)
        self._scopes: dict[str, list[str]] = {}
        self._inherited: dict[tuple[str, str], str | None] = {}
        self._by_meth: dict[str, set[str]] | None = None
        self._by_last: dict[str, list[str]] | None = None  # classes by last name part
        self._overs: dict[str, list[str]] | None = None  # function keys by key without '#N'
        self.own_said: list[Note] = []
        self._free: dict[str, list[str]] | None = None  # free functions by last name part
        self._targs_at: dict[tuple[Any, ...], list[list[str]]] | None = None  # call_targs by their site
        self.py = bool(self.recs) and all(r.get("lang") == "py" for r in self.recs.values())
        self.classes = [] if self.py else sorted(self.units)
        self.entry = prog.units if prog.units is not None else entry_units
        self.sites: dict[str, list[tuple[list[Any], dict[str, Any], str | None]]] = {}
        self.site_at: dict[str, list[Src]] = {}  # where each of those call sites is
        self.site_targs: dict[str, list[tuple[list[str], str | None]]] = {}
        self._targ_seen: dict[tuple[str, str | None, str | None, int], int] = {}
        # what runs what: "U:class" (constructed: all its methods run) and "F:function" (called)
        self.edges: dict[str, set[str]] = {}
        self._link_calls(prog)
        self.reach = self._reach({f"U:{u}" for u in self.entry})
        self._memo: dict[str, list[dict[int, Any]]] = {}
        self._stack: set[str] = set()
        self.pins: dict[str, int] = {}

    def _merge_records(self, prog: Program) -> set[str]:
        """The program's files' records merged (a header read by several
        files counted once); returns the units its entry files define."""
        entry_units: set[str] = set()
        bare_twice: set[str] = set()
        for r in self.recs.values():  # a header read by several files: its definitions once
            self.fn_tparams.update(r.get("fn_tparams", {}))
            self.call_targs += [tuple(c) for c in r.get("call_targs", []) if tuple(c) not in self.call_targs]
            for k, entries in r.get("returns", {}).items():
                self.returns.setdefault(k, [])
                self.returns[k] += [tuple(e) for e in entries if tuple(e) not in self.returns[k]]
        for f, r in self.recs.items():
            for k, (unit, params, ptypes, defaults) in r.get("fns", {}).items():
                old = self.fns.get(k)
                if old is not None and len(old[1]) == len(params):
                    defaults = [d if d is not None else o for d, o in zip(defaults, old[3])]
                self.fns[k] = (unit, params, ptypes, defaults)
                if f in prog.entry:
                    entry_units.add(unit)
            for u, info in r.get("units", {}).items():
                cur = self.units.setdefault(u, {"bases": [], "members": {}})
                cur["bases"] += [b for b in info["bases"] if b not in cur["bases"]]
                cur["members"].update(info["members"])
                cur.setdefault("refs", []).extend(r for r in info.get("refs", []) if r not in cur["refs"])
                if info.get("tparams"):
                    cur["tparams"] = info["tparams"]
                if f in prog.entry:
                    entry_units.add(u)
            for key, vals in r.get("fields", {}).items():
                self.fields.setdefault(key, []).extend(vals)
            for k, v in r.get("callbacks", {}).items():
                self.callbacks.setdefault(k, v)
            for k, v in r.get("aliases", {}).items():
                if "::" not in k and self.aliases.get(k, v) != v:
                    bare_twice.add(k)  # two files give one bare name two texts: read only in its scope
                self.aliases.setdefault(k, v)
            for c in r.get("calls", []):
                self.calls.append(tuple(c) + (({},) if len(c) == 6 else ()))
            if r.get("lang") == "py":
                entry_units.add(f"{f}::<module>")  # a module's code runs when it is imported
        for k in bare_twice:
            self.aliases.pop(k, None)
        return entry_units

    def _link_calls(self, prog: Program) -> None:
        """What runs what (:attr:`edges`) and the call sites of each function
        (:attr:`sites`): a class's methods, the calls read, a plugin's entry
        points, the classes a class holds or derives from."""
        overloaded = {k.split("#")[0] for k in self.fns if "#" in k}  # constructors run only where called
        for k, (unit, *_rest) in self.fns.items():
            if (unit in self.units or unit == k) and "#" not in k and k not in overloaded:
                self._edge(f"U:{unit}", f"F:{k}")
            if unit == k:
                self._edge(f"F:{k}", f"U:{unit}")
        for c in self.calls:
            kind, callee, args, fkey, unit, _src, kwargs = c
            ck, cu = self._callee(kind, callee, unit)
            here = f"F:{fkey}" if fkey else f"U:{unit}" if unit else None
            made = kind in ("ctor", "member") or (ck is not None and cu is not None and (
                ck.endswith(".__init__") or ck == self._ctor(cu)))
            if here is not None and cu is not None and made:
                self._edge(here, f"U:{cu}")
            for k in self.overloads(ck, len(args)) if ck is not None else []:
                if here is not None:
                    self._edge(here, f"F:{k}")
                self.sites.setdefault(k, []).append((args, kwargs, fkey))
                self.site_at.setdefault(k, []).append(_src)
                self.record_site(k, callee, fkey, kind, unit, len(args))
        # a delegating constructor's call (Sensor(o) : Sensor("sensor", o)) is no construction read
        made_outside = {s.split("#")[0] for s, sites in self.sites.items()
                        if any((c or "").split("#")[0] != s.split("#")[0] for _a, _k, c in sites)}
        for k, (unit, *_rest) in self.fns.items():  # an overload's class made where no call is read: all run
            outside = k.split("#")[0] in made_outside
            if ("#" in k or k in overloaded) and not outside:
                self._edge(f"U:{unit}", f"F:{k}")
        if prog.instance is not None:  # a plugin's methods its loader calls, given the instance's name
            for k, got in plugins.entry_sites(self.fns, set(prog.units or ()), set(self.sites), prog.instance).items():
                self.sites[k] = list(got)
                self.site_at.pop(k, None)  # a plugin's entry points: no call site to name
                self.site_targs[k] = [([], None)] * len(got)
        for u, info in self.units.items():
            for ty in list(info["members"].values()) + info["bases"]:
                for ident in _IDENT.findall(ty):
                    m = self.match(ident, u) if not ident.startswith(("std::", "ros::", "rclcpp::")) else None
                    if m is not None and m != u:
                        self._edge(f"U:{u}", f"U:{m}")
            for b in info["bases"] if self.py else []:  # a Python base class of the package runs with it
                m = self._py_base(u, b)
                if m is not None and m != u:
                    self._edge(f"U:{u}", f"U:{m}")

    def _py_base(self, unit: str, base: str) -> str | None:
        """The program's Python class that base ``base`` (as written in class
        ``unit``'s ``class C(base)``) names: a class of the same file, else the
        one the file imports under that name (``from pkg.base import Joint``),
        found in the package."""
        f = unit.split("::", 1)[0]
        if f"{f}::{base}" in self.units:
            return f"{f}::{base}"
        head, _, rest = base.partition(".")
        origins = [o for o in self.recs.get(f, {}).get("imports", [])
                   if o.rsplit(".", 1)[-1] == head or o == head]
        for o in origins[:1] if len(origins) == 1 else []:
            hit = self.code.module(o + ("." + rest if rest else ""))
            if hit is not None and hit[1] and f"{hit[0]}::{hit[1]}" in self.units:
                return f"{hit[0]}::{hit[1]}"
        return None

    # -- program structure
    def match(self, name: str, caller: str | None) -> str | None:
        """The program's class a C++ type name (``Sensor``, ``ns::Sensor``) names."""
        t = split_template(name.replace("*", "").replace("&", "").strip())[0].strip(":")
        if not t:
            return None
        cands = self._classes_named(t)
        for _ in range(4):  # using Filter = ns::FilterNode<Ekf>; make_shared<Filter>(...), or ns::Filter
            if cands:
                break
            alias = alias_of(t, self.aliases, self.scopes(caller), self.alias_index) or \
                alias_of(t.split("::")[-1], self.aliases, (), self.alias_index)
            if alias is None:
                break
            t = split_template(alias.replace(" ", ""))[0].strip(":")
            cands = self._classes_named(t)
        if not cands:
            return None
        if len(cands) > 1 and caller:
            ns = caller.rsplit("::", 1)[0]
            near = [u for u in cands if u.startswith(ns + "::")]
            cands = near or cands
        return sorted(cands, key=len)[0]

    def callee(self, kind: str, callee: str, unit: str | None, nargs: int | None = None) -> tuple[str | None, str | None]:
        """``(callable key, unit)`` a call record names in this program; of a
        constructor's overloads (keys ``Cls::Cls#N``), the one whose parameters
        take ``nargs`` arguments when exactly one does."""
        ck, cu = self._callee(kind, callee, unit)
        if ck is None or nargs is None:
            return ck, cu
        fit = self.overloads(ck, nargs)
        return (fit[0] if len(fit) == 1 else ck), cu

    def overloads(self, ck: str, nargs: int) -> list[str]:
        """The keys of the overloads of ``ck`` (``Cls::Cls``, ``Cls::Cls#N``) a call with
        ``nargs`` arguments may run: those whose parameters, less the defaulted ones,
        take that many; when several do (their argument types would decide), all of
        them; ``[ck]`` when none does or ``ck`` has no overload."""
        if self._overs is None:
            self._overs = {}
            for k in self.fns:
                self._overs.setdefault(k.split("#")[0], []).append(k)
        over = [k for k in self._overs.get(ck.split("#")[0], []) if k == ck or k.startswith(ck + "#")]
        if len(over) <= 1:
            return [ck]
        fit = [k for k in over if len(self.fns[k][1]) - self.optional.get(k, 0) <= nargs <= len(self.fns[k][1])]
        return fit or [ck]

    def _callee(self, kind: str, callee: str, unit: str | None) -> tuple[str | None, str | None]:
        if self.py:
            return self._py_callee(callee)
        if kind == "own-node":  # a member made here that runs on a node of its own: no class of the program
            return None, None
        if kind == "member":
            info = self.units.get(unit or "", {})
            ty = info.get("members", {}).get(callee)
            cls = self.match(_held(ty), unit) if ty else None
            if cls is not None and callee in info.get("refs", []):
                return None, cls  # a reference member bound to what the constructor is given: nothing made
            if cls is not None and _held(ty) != split_template(ty.replace(" ", ""))[0].replace("*", "").strip():
                return None, cls  # a pointer member: made by the new/make_shared it is given
            base = callee.split("<")[0].split("::")[-1]  # ClientBase<ServiceT>(node, name): a template base
            if cls is None and any(b.split("<")[0].split("::")[-1] == base for b in info.get("bases", [])):
                cls = self.match(callee, unit)
            if cls is None and unit and base == unit.split("::")[-1]:  # a delegating constructor
                cls = unit
            return (self._ctor(cls), cls) if cls else (None, None)
        if kind == "ctor":
            cls = self.match(callee, unit)
            return (self._ctor(cls), cls) if cls else (None, None)
        meth, recv = callee, None
        for sep in ("->", "."):
            if sep in meth:
                recv, meth = meth.rsplit(sep, 1)
        if "::" in meth and recv is None:
            head, last = meth.rsplit("::", 1)
            cls = self.match(head, unit)
            if cls is not None and f"{cls}::{last}" in self.fns:
                return f"{cls}::{last}", cls
            cls = self.match(meth, unit)
            if cls is not None:
                return self._ctor(cls), cls
        if recv is not None and recv.replace("this", "").strip("()*&") and unit:
            held = recv.replace("this->", "").strip()
            if held.endswith("]") and "[" in held:  # an element of a member container: leds_[i]->on()
                held = held[:held.index("[")]
            ty = self.units.get(unit, {}).get("members", {}).get(held)
            cls = self.match(_held(ty), unit) if ty else None
            if ty is None and "->" not in recv and "." not in recv:  # a local (auto node = shared_from_this())
                own = self.inherited(unit, meth)
                if own is not None and self.methods_named(meth) == {own}:
                    return own, self.fns[own][0]
            return (f"{cls}::{meth}", cls) if cls and f"{cls}::{meth}" in self.fns else (None, None)
        if unit and (own := self.inherited(unit, meth)) is not None:
            return own, self.fns[own][0]
        cls = self.match(meth, unit)
        if cls is not None and recv is None:
            return self._ctor(cls), cls
        if self._free is None:
            self._free = {}
            for k, v in self.fns.items():
                if v[0] == k:
                    self._free.setdefault(k.rsplit("::", 1)[-1], []).append(k)
        free = [k for k in self._free.get(meth.rsplit("::", 1)[-1], []) if k == meth or k.endswith("::" + meth)]
        return (free[0], free[0]) if len(free) == 1 else (None, None)

    def _classes_named(self, t: str) -> list[str]:
        """The program's classes named ``t`` or ending in ``::t``."""
        if self._by_last is None:
            self._by_last = {}
            for u in self.classes:
                self._by_last.setdefault(u.rsplit("::", 1)[-1], []).append(u)
        return [u for u in self._by_last.get(t.rsplit("::", 1)[-1], []) if u == t or u.endswith("::" + t)]

    def methods_named(self, meth: str) -> set[str]:
        """The keys of the program's class methods (not free functions) named ``meth``."""
        if self._by_meth is None:
            self._by_meth = {}
            for k, v in self.fns.items():
                if v[0] != k and "::" in k:
                    self._by_meth.setdefault(k.split("#")[0].rsplit("::", 1)[1], set()).add(k)
        return self._by_meth.get(meth, set())

    def inherited(self, unit: str, meth: str, depth: int = 0) -> str | None:
        """The key of method ``meth`` as class ``unit`` has it: its own, else the
        nearest base class's of the program (a derived node calling its base's
        ``create_action_server<T>("name", ...)`` unqualified); ``None`` when
        neither defines it."""
        if f"{unit}::{meth}" in self.fns:
            return f"{unit}::{meth}"
        if depth > 8 or not self.methods_named(meth):
            return None
        if (unit, meth) in self._inherited:
            return self._inherited[(unit, meth)]
        self._inherited[(unit, meth)] = None  # a cycle of bases finds nothing
        got = None
        for b in self.units.get(unit, {}).get("bases", []):
            cls = self.match(b, unit)
            got = self.inherited(cls, meth, depth + 1) if cls is not None and cls != unit else None
            if got is not None:
                break
        self._inherited[(unit, meth)] = got
        return got

    def scopes(self, unit: str | None) -> list[str]:
        """The scopes a name written in class ``unit`` is looked up in, innermost
        first: the class, its base classes of the program, then its enclosing
        classes and namespaces (``a::B`` -> ``a::B``, bases, ``a``)."""
        if not unit:
            return []
        if unit in self._scopes:
            return self._scopes[unit]
        self._scopes[unit] = [unit]  # while its bases are matched (a base named through an alias)
        out = [unit] + [b for b in (self.match(x, None) for x in self.units.get(unit, {}).get("bases", [])) if b]
        parts = unit.split("::")
        out += ["::".join(parts[:i]) for i in range(len(parts) - 1, 0, -1)]
        self._scopes[unit] = list(dict.fromkeys(out))
        return self._scopes[unit]

    def _ctor(self, cls: str) -> str:
        return f"{cls}::{cls.split('::')[-1]}"

    def _py_callee(self, callee: str) -> tuple[str | None, str | None]:
        if callee.startswith("ext:"):
            hit = self.code.module(callee[4:])
            if hit is None or not hit[1]:
                return None, None
            callee = f"{hit[0]}::{hit[1]}"
        if callee in self.units:
            return f"{callee}.__init__", callee
        if callee in self.fns:
            return callee, self.fns[callee][0]
        return None, None

    def never_made(self, e: Endpoint) -> bool:
        """Whether endpoint ``e`` lies in a class of the program that nothing the program
        runs constructs, and in none of its methods that run anyway (not an overload
        nobody calls: that is left out by design)."""
        u = e.unit
        if u is None or u not in self.units or "#" in (e.func or "") or f"U:{u}" in self.reach:
            return False
        return not any(f"F:{k}" in self.reach for k, v in self.fns.items() if v[0] == u)

    def _edge(self, a: str, b: str) -> None:
        self.edges.setdefault(a, set()).add(b)

    def runs(self, unit: str | None, fkey: str | None, reach: set[str] | None = None) -> bool:
        """Whether code of function ``fkey`` (else of unit ``unit``) runs in the program
        (or in ``reach``, a set of reached ``U:``/``F:`` items)."""
        reach = self.reach if reach is None else reach
        if fkey is not None and fkey in self.fns:
            return f"F:{fkey}" in reach
        return unit is not None and f"U:{unit}" in reach

    def _reach(self, start: set[str]) -> set[str]:
        seen, todo = set(), list(start)
        while todo:
            u = todo.pop()
            if u in seen:
                continue
            seen.add(u)
            todo.extend(self.edges.get(u, ()))
        return seen

    # -- the program's endpoints and nodes
    def run(self) -> Linked:
        out = Linked()
        said: set[tuple[Src, str]] = set()

        def note(n: Note) -> None:
            if (n.src, n.message) not in said:
                said.add((n.src, n.message))
                out.notes.append(n)

        raw: list[tuple[str, Endpoint]] = []
        unbuilt: list[Endpoint] = []
        for f, r in self.recs.items():
            for e in list(r.get("endpoints", [])) + self.members(r):
                if e.unit is None and e.func is None and f not in self.prog.entry:
                    continue
                if (e.unit is not None or e.func is not None) and not self.runs(e.unit, e.func):
                    root = self.code.root.rstrip("/")
                    if (root in ("", ".") or f.startswith(root + "/")) and self.never_made(e):
                        unbuilt.append(e)
                    continue
                raw.append((f, e))
        for n in self.own_said:
            note(n)
        named = self.named(note, out)
        unused = self.prog.exe is None and self.prog.units is None and not named and \
            all(f.rsplit(".", 1)[-1] in ("h", "hh", "hpp", "hxx") for f in self.prog.entry)
        # said even when the program names no node (never a silent miss), but for a plugin, whose
        # loader makes it (plugins.py says so at each endpoint)
        plugin = self.prog.plugin is not None or self.prog.instance is not None
        for e in unbuilt if named or not (unused or plugin) else []:
            note(Note(e.src, f"{emit.WHAT[e.kind]} of class {e.unit}: {UNBUILT}"))
        self.user_creates(note)
        out.nodes = [(n, s, ns) for n, s, ns, _u, _p in named]
        units = [u for _n, _s, _ns, u, _p in named]
        got: list[tuple[Endpoint, int]] = []
        # a header no program of the package includes: its classes are for other packages to
        # make, with the names they give; what they leave open is not this package's to say
        say = (lambda n: None) if unused else note
        for (f, e), own in zip(raw, self.owners(units, [e for _f, e in raw])):
            # one class made as several nodes (each call site its own name): each instance
            # reads the endpoint with the arguments of its own call site (docs/ros.md)
            group = [j for j, it in enumerate(named) if own >= 0 and it[3] == units[own] and it[1] == named[own][1]]
            for j in group if len(group) > 1 else [own]:
                self.pin(named[j][4] if len(group) > 1 else {})
                for x in self.resolve(e, say):
                    if (x, j) not in got:
                        got.append((x, j))
                        if f not in out.files:
                            out.files.append(f)
        self.pin({})
        out.endpoints = got
        return out

    def named(self, note: Callable[[Note], None], out: Linked) -> list[tuple[str, Src, str | None, str | None,
                                                                          dict[str, int]]]:
        """The program's nodes: ``[(name, where named, namespace, unit, pins)]``; a node
        name read from the arguments of a function called at several sites (a node
        class constructed twice) is read site by site, ``pins`` naming the site."""
        named: list[tuple[str, Src, str | None, str | None, dict[str, int]]] = []
        for f, r in self.recs.items():
            for v, src, unit, fkey, ns, *more in r.get("node_names", []):
                kind, opts = (more + [None, None])[:2]
                if (unit is not None or fkey is not None) and not self.runs(unit, fkey) \
                        or unit is None and fkey is None and f not in self.prog.entry:
                    continue
                live = [i for i, (_a, _k, caller) in enumerate(self.sites.get(fkey or "", []))
                        if caller is None or self.runs(None, caller)]
                pinned = len(live) > 1 and not symbols.is_concrete(v)
                for pins in [{fkey: i} for i in live] if pinned and fkey else [{}]:
                    self.pin(pins)
                    for env in self.contexts(fkey):
                        remap = self.remapped(opts, ns, env, fkey)
                        for name in self.eval(v, env, fkey) if remap[0] is None else [symbols.lit(remap[0])]:
                            t = symbols.text(name) if name is not None and name[0] in ("str", "cat") else None
                            if t is None:
                                note(Note(src, "node name is not a string literal: not resolved statically"))
                                continue
                            bad = names.node_name_problem(t)
                            if bad is not None:  # never the node '/': its endpoints stay off the graph
                                note(Note(src, f"node name {bad}: not resolved statically; its endpoints are "
                                               f"not in the graph"))
                                continue
                            nsv = self.eval(ns, env, fkey)[0] if ns is not None and not remap[2] else None
                            if remap[1] is not None:  # NodeOptions' __ns:= remap
                                nsv = symbols.lit(remap[1])
                            elif ns is not None and (nsv is None or symbols.text(nsv) is None) and not remap[2]:
                                note(Note(src, f"namespace of node '{t}' is not a string literal: not resolved "
                                               f"statically (the root namespace is shown unless a launch file "
                                               f"gives one)"))
                                nsv = None
                            # "" and no namespace are the same (a base's default ns = "")
                            item = (t, src, (symbols.text(nsv) or None) if nsv is not None else None,
                                    self.made_as(unit, fkey, pins), pins)
                            if not any(x[0] == t and x[2] == item[2] for x in named):
                                named.append(item)
                                out.kinds.append(kind)
                            if f not in out.files:
                                out.files.append(f)
        self.pin({})
        return named

    def made_as(self, unit: str | None, fkey: str | None, pins: dict[str, int]) -> str | None:
        """The class a node named in ``unit``'s constructor ``fkey`` is, read at the
        call site ``pins`` names: a base class's constructor called from a derived
        class's constructor (``Odometer(name) : ManagedNode(name)``) makes a node of
        the derived class, whose own endpoints are that node's; else ``unit``."""
        if unit is None or fkey is None or fkey not in pins or fkey.split("#")[0] != self._ctor(unit):
            return unit
        sites = self.sites.get(fkey, [])
        caller = sites[pins[fkey]][2] if pins[fkey] < len(sites) else None
        cunit = self.fns[caller][0] if caller is not None and caller in self.fns else None
        if caller is None or cunit is None or cunit == unit or caller.split("#")[0] != self._ctor(cunit) or \
                f"U:{unit}" not in self._reach({f"U:{cunit}"}):
            return unit
        return cunit

    def user_creates(self, note: Callable[[Note], None]) -> None:
        """A located note at each call of a user's method named like rclcpp's
        (``bus.create_publisher(node, "t")``, :mod:`sources_cpp`) whose body is
        not in the program: it is not rclcpp's, so nothing is guessed from it."""
        for r in self.recs.values():
            for callee, unit, fkey, src, *why in r.get("user_creates", []):
                ck, _cu = self.callee("call", callee, unit)
                if self.runs(unit, fkey) and (ck is None or ck not in self.fns):
                    said = why[0] if why else "takes the node first"
                    note(Note(src, f"{callee}(...) {said}, so it is no rclcpp method, and its body "
                                   f"is not in the workspace: its endpoints are not read"))

    def pin(self, pins: dict[str, int]) -> None:
        """Read function ``k``'s parameters from its call site ``pins[k]`` only."""
        if pins != self.pins:
            self.pins = pins
            self._memo.clear()

    def resolve(self, e: Endpoint, note: Callable[[Note], None]) -> list[Endpoint]:
        """The concrete endpoints a (possibly pending) endpoint stands for."""
        if e.pending is None:
            return [e]
        name, handle, cb, fkey, written, nsrc = e.pending
        if self.uninstantiated(name):
            return []  # made only by a template this program never instantiates: nothing to say
        # a template's own parameter (ActionT) names no alias of another class ([temp.local]):
        # its type is read per instantiation below, never through the program's aliases
        own = isinstance(cb, tuple) and cb[:1] == ("type",) and is_template_param(cb[1], e.unit, e.func, self)
        t = e.msg_type if e.msg_type is not None else None if own else self.cb_type(e.kind, cb, e.unit)
        types: list[str | None] = [t]
        ambiguous = False
        if t is None and isinstance(cb, tuple) and cb[:1] == ("type",):  # a template's type parameter
            each = self.per_instance(e, note)
            if each is not None:
                return each
            types, ambiguous = self.template_candidates(e, note)
            t = types[0]
        argtype = cb if isinstance(cb, tuple) and cb[:1] == ("argtype",) else None
        got: list[Endpoint] = []
        outer = self.pins
        for via in self.name_sites(fkey, name):
            if via is not None:  # read at that call site only, the edge naming it
                self.pin({**outer, fkey: via[0]})
            for env in self.contexts(fkey):
                if argtype is not None:  # a Python helper's type parameter, read at each call site
                    types = [_py_typed(v, e.kind) for v in self.eval(("arg", argtype[1], argtype[2]), env, fkey)] \
                        or [None]
                    t = types[0] if all(types) else None
                for n in self.eval(name, env, fkey):
                    for h in self.eval(handle, env, fkey) if handle is not None else [None]:
                        if n is not None and n[0] == "ops":
                            n = n[2]
                        for ty in types:
                            x, bad = emit.resolve(e.kind, n, h, ty, e.src, e.unit, written, nsrc, e.func)
                            if bad is not None:
                                note(bad)
                            if x is not None and via is not None:
                                x = replace(x, via=via[1])
                            if x is not None and x not in got:
                                got.append(x)
        self.pin(outer)
        if got and t is None and not ambiguous:
            note(emit.type_note(got[0]))
        return got

    def name_sites(self, fkey: str | None, name: Any) -> list[tuple[int, Src] | None]:
        """The call sites an endpoint's name is read at one by one: ``[(index in
        sites[fkey], where)]`` when the name reads a parameter of function ``fkey``
        and ``fkey`` has several call sites that run (at most :data:`MAX_VALUES`,
        none pinned already), so each edge names the call whose argument gives it;
        else ``[None]`` (every call site at once)."""
        at = self.site_at.get(fkey or "", [])
        sites = self.sites.get(fkey or "", [])
        if fkey is None or fkey in self.pins or len(at) != len(sites) or fkey not in _homes(name):
            return [None]
        live = [(i, at[i]) for i, (_a, _k, caller) in enumerate(sites) if caller is None or self.runs(None, caller)]
        return list(live) if 1 < len(live) <= MAX_VALUES else [None]

    def uninstantiated(self, v: Any, depth: int = 0) -> bool:
        """Whether name value ``v`` reaches the program only through parameters of
        templates nothing in the program calls: a function template, or a
        function of a class template, with no call site that runs (a library's
        ``create_action_server<T>(name)`` member the program never calls).  C++
        instantiates such a template only where it is used ([temp.inst]), so
        the endpoint it would make does not exist in this program; a template
        with a site, and any other function, is never taken as uncalled."""
        if v is None or not isinstance(v, tuple) or depth > MAX_DEPTH:
            return False
        if v[0] == "cat":
            return any(self.uninstantiated(x, depth + 1) for x in v[1])
        if v[0] == "field":
            binds = self.fields.get((v[1], v[2])) or []
            return bool(binds) and all(self.uninstantiated(b, depth + 1) for b in binds)
        if v[0] != "arg" or v[1] not in self.fns:
            return False
        key = v[1]
        live = [(a, caller) for a, _kw, caller in self.sites.get(key, []) if caller is None or self.runs(None, caller)]
        if not live:
            unit = self.fns[key][0]
            return bool(self.fn_tparams.get(key) or self.fn_tparams.get(key.split("#")[0])
                        or self.units.get(unit, {}).get("tparams"))
        return all(v[2] < len(a) and self.uninstantiated(a[v[2]], depth + 1) for a, _c in live)

    def owners(self, units: list[str | None], eps: list[Endpoint]) -> list[int]:
        """Each endpoint's node (an index in the named nodes; -1 when none)."""
        if len(units) <= 1:
            return [0 if units else -1] * len(eps)
        reach = {i: self._reach({f"U:{u}"}) if u else set() for i, u in enumerate(units)}
        loose = next((i for i, u in enumerate(units) if u is None or u not in self.units or u.endswith("<module>")), 0)
        out = []
        for e in eps:
            own = next((i for i, u in enumerate(units) if u is not None and u == e.unit), None)
            if own is None and self.py:  # a nested class belongs to its enclosing node class
                inner = [i for i, u in enumerate(units) if u and u in self.units and (e.unit or "").startswith(u + ".")]
                own = max(inner, key=lambda i: len(units[i] or "")) if inner else None
            if own is None:
                own = next((i for i in reach if units[i] in self.units and self.runs(e.unit, e.func, reach[i])), loose)
            out.append(own)
        return out


def _py_typed(v: Any, kind: str) -> str | None:
    """The ROS type a Python value names (``("ext", "std_srvs.srv.Trigger")``) for role ``kind``."""
    from rclverify.ros.extract.sources_py import _typed  # deferred: start-up (loads rclverify.ros.extract and more only when called)
    return _typed(v[1], kind) if v is not None and v[0] == "ext" and isinstance(v[1], str) else None


def _held(ty: str | None) -> str:
    """The class a member's type holds: ``std::shared_ptr<ns::Sensor>`` -> ``ns::Sensor``."""
    if not ty:
        return ""
    head, args = split_template(ty.replace(" ", ""))
    if head.split("::")[-1] in ("shared_ptr", "unique_ptr", "weak_ptr", "Ptr", "SharedPtr", "vector", "optional",
                                "array", "deque", "list") and args:
        return _held(args[0])
    if head.split("::")[-1] in ("map", "unordered_map") and len(args) == 2:  # a map's element is its value
        return _held(args[1])
    return head
