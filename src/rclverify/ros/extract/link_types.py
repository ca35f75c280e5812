"""One message type per endpoint of a template (docs/ros.md, "One type per
call site"): the linker's reading of a class template's or function
template's type parameter construction by construction, call by call.

A class template ``template<typename ServiceT> class Client`` whose
constructor makes ``create_client<ServiceT>(name)`` and that the program
constructs twice (``Client<Trigger>(node, "estop")``, ``Client<SetBool>(node,
"arm")``) has two endpoints, ``estop`` of type ``Trigger`` and ``arm`` of
type ``SetBool``: each construction's template argument is read together
with the arguments of the same construction (the site is *pinned*, as
:meth:`~.link.Linker.pin` pins a node class's sites), followed through a
derived template's base initialiser (``Caller<T> : ClientBase<T>``) and a
function template's explicit template argument (``make_sub<T>(node, topic)``).
Where no construction or call gives the argument together with the name, and
the template stands for several types, the endpoint is one, its type unknown,
with a located note naming the candidate types and why; never one endpoint
per candidate type (C++ [temp.inst]: a template's code is instantiated per
template argument list).  Mixed into :class:`~.link.Linker`.
"""
from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Any, Callable

from rclverify.ros.extract import emit
from rclverify.ros.extract.cpp_types import alias_of, split_template
from rclverify.ros.extract.model import Endpoint, Note
from rclverify.ros.extract.link_units import UnitInfo, unit_of

#: instantiations read per endpoint at most (bounded work)
MAX_INSTANCES = 32


class Instances:
    """Template arguments per construction or call site (see the module docstring)."""

    fns: dict[str, tuple[str, list[str], list[str], list[Any]]]
    units: dict[str, UnitInfo]
    fn_tparams: dict[str, list[str]]
    aliases: dict[str, str]
    alias_index: dict[str, list[str]]
    call_targs: list[tuple[str, str | None, str | None, int, list[str]]]
    _targ_seen: dict[tuple[str, str | None, str | None, int], int]
    _targs_at: dict[tuple[Any, ...], list[list[str]]] | None
    sites: dict[str, list[tuple[list[Any], dict[str, Any], str | None]]]
    #: per function key, parallel to ``sites``: the template arguments written at each
    #: site (``Client<pkg::srv::T>(...)``: ``["pkg::srv::T"]``) and the calling function
    site_targs: dict[str, list[tuple[list[str], str | None]]]

    pins: dict[str, int]

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def runs(self, unit: str | None, fkey: str | None, reach: set[str] | None = None) -> bool:
            ...

        def pin(self, pins: dict[str, int]) -> None:
            ...

        def resolve(self, e: Endpoint, note: Callable[[Note], None]) -> list[Endpoint]:
            ...

        def cb_type(self, kind: str, cb: Any, unit: str | None = None) -> str | None:
            ...

        def template_types(self, unit: str | None, param: str, depth: int = 0) -> list[str]:
            ...

        def fn_template_types(self, fkey: str | None, param: str, depth: int = 0) -> list[str]:
            ...

    def per_instance(self, e: Endpoint, note: Callable[[Note], None]) -> list[Endpoint] | None:
        """The endpoints of pending endpoint ``e``, whose type is a template parameter,
        read instantiation by instantiation (each construction or call pinned, its
        own template argument the type); ``None`` when no site writes the argument."""
        name, handle, cb, fkey, written, nsrc = e.pending
        per_site = self.instances(e.unit, e.func, cb[1])
        if not per_site:
            return None
        saved, each = dict(self.pins), []
        for pins, text in per_site:
            self.pin({**saved, **pins})
            typed = dataclasses.replace(e, msg_type=self.cb_type(e.kind, ("type", text)) if text else None,
                                        pending=(name, handle, None, fkey, written, nsrc))
            each += [x for x in self.resolve(typed, note) if x not in each]
        self.pin(saved)
        return each

    def template_candidates(self, e: Endpoint, note: Callable[[Note], None]) -> tuple[list[str | None], bool]:
        """``([type], ambiguous)`` of pending endpoint ``e`` whose template parameter no
        site gives with its name: the one type every instantiation gives, else
        ``[None]`` and a located note naming the candidates (never one endpoint each)."""
        cb, written = e.pending[2], e.pending[4]
        cands = list(dict.fromkeys(self.cb_type(e.kind, ("type", x)) for x in self.template_types(e.unit, cb[1])
                                   or self.fn_template_types(e.func, cb[1])))
        if len(cands) <= 1:
            return (cands or [None]), False
        shown = ", ".join(c or "(unread)" for c in cands)
        note(Note(e.src, f"type of {emit.WHAT[e.kind]} '{written}' is ambiguous: template parameter {cb[1]} is one "
                         f"of {shown}, and no construction or call read gives it together with the name: the "
                         f"endpoint is kept with no type"))
        return [None], True

    def record_site(self, key: str, callee: str, caller: str | None, kind: str = "ctor", unit: str | None = None,
                    nargs: int = 0) -> None:
        """Keep the template arguments ``callee`` is written with, for the site of
        ``key`` just appended to ``sites[key]``: a member initialised in a constructor
        (``halt_(this, "halt")``) has those of its declared type (``Client<Trigger>
        halt_;``), a function template's call those the file read for it, in order."""
        if kind == "member":
            callee = unit_of(self.units, unit).members.get(callee, callee)
        elif kind == "call" and "<" not in callee:
            same = (callee, unit, caller, nargs)
            k = self._targ_seen.get(same, 0)
            self._targ_seen[same] = k + 1
            if self._targs_at is None:
                self._targs_at = {}
                for c in self.call_targs:
                    self._targs_at.setdefault(tuple(c[:4]), []).append(c[4])
            written = self._targs_at.get(same, [])
            if k < len(written):
                self.site_targs.setdefault(key, []).append((list(written[k]), caller))
                return
        text = callee.replace(" ", "").split("->")[-1].split(".")[-1]
        for _ in range(4):  # a using alias of an instantiation: using Filter = FilterNode<Ekf>
            alias = alias_of(text, self.aliases, (), self.alias_index) or \
                alias_of(split_template(text)[0], self.aliases, (), self.alias_index)
            if alias is None or "<" in text:
                break
            text = alias.replace(" ", "")
        self.site_targs.setdefault(key, []).append((split_template(text)[1], caller))

    def instances(self, unit: str | None, fkey: str | None, param: str, depth: int = 0
                  ) -> list[tuple[dict[str, int], str | None]]:
        """``[(pins, type text)]``: for each construction of class template ``unit``
        (its constructor's sites) or each call of function template ``fkey`` whose
        template argument for ``param`` is written there, the site to pin
        (``{function key: site index}``) and that argument; through a caller's own
        template parameter, the caller's sites too; a site that does not write it
        (a deduced argument) gives ``None`` beside those that do.  ``[]`` when no
        site writes it."""
        if depth > 4:
            return []
        cls_tps = unit_of(self.units, unit).tparams
        fn_base = (fkey or "").split("#")[0]
        fn_tps = self.fn_tparams.get(fkey or "", self.fn_tparams.get(fn_base, []))
        if param in fn_tps and fkey:
            keys, i = [k for k in self.site_targs if k.split("#")[0] == fn_base], fn_tps.index(param)
        elif param in cls_tps and unit:
            ctor = f"{unit}::{unit.split('::')[-1].split('<')[0]}"
            keys, i = [k for k in self.site_targs if k.split("#")[0] == ctor], cls_tps.index(param)
        else:
            return []
        return self._at_sites(keys, i, unit if param in cls_tps and param not in fn_tps else None, depth)

    def _at_sites(self, keys: list[str], i: int, cls: str | None, depth: int
                  ) -> list[tuple[dict[str, int], str | None]]:
        """:meth:`instances` read at the sites of ``keys``, the template argument
        the ``i``-th; ``cls`` the class template whose parameter it is (``None``:
        a function template's).  A constructor of ``cls`` delegating to another
        (``Host(node, n) : Host(node->base(), n)``) writes no argument: the
        delegated-to constructor runs in the delegating one's instantiation, so
        the delegating constructor's own sites give it."""
        out: list[tuple[dict[str, int], str | None]] = []
        unwritten: list[tuple[dict[str, int], str | None]] = []  # sites whose argument is deduced
        for k in sorted(keys):
            for j, (targs, caller) in enumerate(self.site_targs[k]):
                if caller is not None and not self.runs(None, caller):
                    continue
                cunit = self.fns[caller][0] if caller in self.fns else None
                if len(targs) <= i and cls is not None and caller is not None and cunit == cls and \
                        caller.split("#")[0] == k.split("#")[0] and caller != k and depth <= 4:
                    for pins, text in self._at_sites([caller], i, cls, depth + 1):
                        item = ({**pins, k: j}, text)
                        if item not in out:
                            out.append(item)
                    continue
                if len(targs) <= i:
                    unwritten.append(({k: j}, None))
                    continue
                arg = targs[i]
                inner = self.instances(cunit, caller, arg, depth + 1) if caller is not None else []
                for pins, text in inner or ([({}, arg)] if not is_template_param(arg, cunit, caller, self) else []):
                    item = ({**pins, k: j}, text)
                    if item not in out:
                        out.append(item)
                if len(out) >= MAX_INSTANCES:
                    return out
        # a site whose argument is not written (deduced) keeps its name, its type unread
        return out + unwritten if out else []


def is_template_param(arg: str, unit: str | None, fkey: str | None, lk: Instances) -> bool:
    """Whether type text ``arg`` is a template parameter of class ``unit`` or
    function ``fkey`` (not a type); ``lk`` the linker holding their tables."""
    return arg in unit_of(lk.units, unit).tparams or \
        arg in lk.fn_tparams.get(fkey or "", lk.fn_tparams.get((fkey or "").split("#")[0], []))
