"""The linker's index of one program: the records of the files it runs
merged once, and the lookups every part of the linker makes in them
(docs/ros.md, "Reading real code").

:meth:`LinkIndex._merge_records` merges the per-file records (functions,
classes, members, aliases, calls, returns; a header read by several files
counted once).  On that index: the program's class a C++ type name names
(:meth:`LinkIndex.match`, through aliases and the caller's scopes), the
function and class a call record runs (:meth:`LinkIndex.callee`, a
constructor's overloads by their parameter count), a method as a class has
it through its bases (:meth:`LinkIndex.inherited`) and the scopes a name is
looked up in (:meth:`LinkIndex.scopes`).  Mixed into
:class:`~.link.Linker`, which provides the attributes annotated on the
class.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract.cpp_types import alias_of, split_template
from rclverify.ros.extract.link_returns import Entry
from rclverify.ros.extract.link_units import UnitInfo, unit_of
from rclverify.ros.extract.programs import PackageCode, Program


class LinkIndex:
    """The program's merged records and the lookups in them (module docstring)."""

    recs: dict[str, dict[str, Any]]
    code: PackageCode
    fns: dict[str, tuple[str, list[str], list[str], list[Any]]]
    units: dict[str, UnitInfo]
    fields: dict[tuple[str, str], list[Any]]
    callbacks: dict[str, str]
    aliases: dict[str, str]
    alias_index: dict[str, list[str]]
    calls: list[tuple[Any, ...]]
    optional: dict[str, int]  # function key -> how many of its parameters have a default
    returns: dict[str, list[Entry]]
    fn_tparams: dict[str, list[str]]
    call_targs: list[tuple[str, str | None, str | None, int, list[str]]]
    py: bool  # a Python program (every file's record is Python's)
    classes: list[str]  # the program's C++ classes (none for a Python program)
    _scopes: dict[str, list[str]]
    _inherited: dict[tuple[str, str], str | None]
    _by_meth: dict[str, set[str]] | None
    _by_last: dict[str, list[str]] | None
    _overs: dict[str, list[str]] | None
    _free: dict[str, list[str]] | None

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
                cur = self.units.setdefault(u, UnitInfo())
                cur.bases += [b for b in info["bases"] if b not in cur.bases]
                cur.members.update(info["members"])
                cur.refs.extend(r for r in info.get("refs", []) if r not in cur.refs)
                if info.get("tparams"):
                    cur.tparams = info["tparams"]
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
            info = unit_of(self.units, unit)
            ty = info.members.get(callee)
            cls = self.match(_held(ty), unit) if ty else None
            if cls is not None and callee in info.refs:
                return None, cls  # a reference member bound to what the constructor is given: nothing made
            if cls is not None and ty and _held(ty) != split_template(ty.replace(" ", ""))[0].replace("*", "").strip():
                return None, cls  # a pointer member: made by the new/make_shared it is given
            base = callee.split("<")[0].split("::")[-1]  # ClientBase<ServiceT>(node, name): a template base
            if cls is None and any(b.split("<")[0].split("::")[-1] == base for b in info.bases):
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
            ty = unit_of(self.units, unit).members.get(held)
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
        for b in unit_of(self.units, unit).bases:
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
        out = [unit] + [b for b in (self.match(x, None) for x in unit_of(self.units, unit).bases) if b]
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
