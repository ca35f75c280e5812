"""What one program runs, for the linker (docs/ros.md, "Reading real code").

The graph of what runs what (:attr:`LinkReach.edges`: ``"U:class"``
constructed, so all its methods run; ``"F:function"`` called) and the call
sites of each function (:attr:`LinkReach.sites`): a class's methods, the
calls read, a plugin's entry points (:mod:`plugins`), the classes a class
holds or derives from (a Python base class found through the file's
imports).  What the entry units reach in it is what the program runs
(:meth:`LinkReach.runs`); an endpoint of a class nothing constructs is
never made (:meth:`LinkReach.never_made`).  Mixed into
:class:`~.link.Linker`, which provides the attributes annotated on the
class.
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import plugins
from rclverify.ros.extract.link_index import LinkIndex
from rclverify.ros.extract.model import Endpoint, Src
from rclverify.ros.extract.programs import Program

_IDENT = re.compile(r"[A-Za-z_][\w:]*")


class LinkReach(LinkIndex):
    """What runs what in the program (module docstring)."""

    edges: dict[str, set[str]]
    reach: set[str]  # the ``U:``/``F:`` items the program's entry units reach
    sites: dict[str, list[tuple[list[Any], dict[str, Any], str | None]]]
    site_at: dict[str, list[Src]]  # where each of those call sites is
    site_targs: dict[str, list[tuple[list[str], str | None]]]

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def record_site(self, key: str, callee: str, caller: str | None, kind: str = "ctor", unit: str | None = None,
                        nargs: int = 0) -> None:
            ...

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
            for ty in list(info.members.values()) + info.bases:
                for ident in _IDENT.findall(ty):
                    m = self.match(ident, u) if not ident.startswith(("std::", "ros::", "rclcpp::")) else None
                    if m is not None and m != u:
                        self._edge(f"U:{u}", f"U:{m}")
            for b in info.bases if self.py else []:  # a Python base class of the package runs with it
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
