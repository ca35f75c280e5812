"""The linker's reading of what classes hold and of callback types
(docs/ros.md, "Reading real code"): the endpoints of helper objects held as
members or inherited as base classes, of helper methods called on members
whose class another file declares, and the message type a callback's
parameter gives.  Mixed into :class:`~.link.Linker`, which provides the
program's tables (``units``, ``calls``, ``callbacks``, ``aliases``,
``known``, ``runs`` and ``match``).

A helper member is made where the constructor's initialiser list names it
(its arguments, its location), else by default at its declaration; a helper
base class likewise, by the initialiser naming the base, else by default at
the base clause (``class Diagnostics : private diagnostic_updater::Updater``).
A helper constructed through a ``typedef`` that another file of the program
declares (``new ReconfigureServer(private_nh)``) is read through the
program's aliases.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

from rclverify.ros.extract import cpp_helpers, symbols
from rclverify.ros.extract.cpp_types import (action_type, action_type_in, alias_of, message_type, service_type,
                                             split_template)
from rclverify.ros.extract.model import Endpoint, Note
from rclverify.ros.extract.link_units import UnitInfo, unit_of

_ACTIONLIB = {"SimpleActionServer": "action_servers", "ActionServer": "action_servers",
              "SimpleActionClient": "action_clients", "ActionClient": "action_clients"}


class LinkMembers:
    """Members, bases and callback types of a linked program (see the module docstring)."""

    units: dict[str, UnitInfo]
    calls: list[tuple[Any, ...]]
    callbacks: dict[str, str]
    aliases: dict[str, str]
    known: Callable[[str], bool]
    using_ns: list[str]  # the program's ``using namespace`` directives
    alias_index: dict[str, list[str]]  # the aliases' keys by last name part (cpp_types.alias_index)
    own_said: list[Note]  # TransformListeners :meth:`members` found on tf2's own node, to be said

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def runs(self, unit: str | None, fkey: str | None, reach: set[str] | None = None) -> bool:
            ...

        def match(self, name: str, caller: str | None) -> str | None:
            ...

        def scopes(self, unit: str | None) -> list[str]:
            ...

    def cb_type(self, kind: str, cb: Any, unit: str | None = None) -> str | None:
        """The type a callback (C++: its name; Python: ``("cands", types)`` of a star
        import), a type text (``("type", text)``) or an interface spec's member
        alias (``("spec", "ns::Spec::Message")``, read only where the program
        declares it) gives an endpoint of role
        ``kind``; an alias in the text is read in the scopes of class ``unit``
        (:func:`~.cpp_types.alias_of`), never another class's of the same name."""
        if isinstance(cb, tuple) and cb and cb[0] == "cands":
            known = [t for t in cb[1] if self.known(t)]
            return known[0] if len(known) == 1 else None
        if isinstance(cb, tuple) and cb and cb[0] == "specof":  # a member declared Publisher<Spec>::SharedPtr
            spec = getattr(self, "spec_of")(cb[1], cb[2])
            if spec is None:
                return None
            cb = ("spec", f"{spec}::{'Message' if kind in ('pub', 'sub') else 'Service'}")
        if isinstance(cb, tuple) and cb and cb[0] == "spec":  # Spec::Message of an interface spec: only as defined
            got = alias_of(cb[1], self.aliases, self.scopes(unit), self.alias_index)
            if got is None:
                return None
            cb = ("type", got)
        if isinstance(cb, tuple) and cb and cb[0] == "type":
            text: str | None = cb[1]
            scopes = self.scopes(unit)
            for _ in range(4):
                text = alias_of(text or "", self.aliases, scopes, self.alias_index) or text
        elif isinstance(cb, str):
            text = self.callbacks.get(cb)
            if text is None:  # written with another qualification than declared
                hits = sorted({v for k, v in self.callbacks.items() if k.endswith("::" + cb) or cb.endswith("::" + k)})
                text = hits[0] if len(hits) == 1 else self.callbacks.get(cb.split("::")[-1])
        else:
            return None
        if kind in ("pub", "sub"):
            return message_type(text, self.aliases)
        return service_type(text) if kind.startswith("service") else action_type(text)

    def template_types(self, unit: str | None, param: str, depth: int = 0) -> list[str]:
        """The type texts template parameter ``param`` of class template ``unit``
        stands for: the template argument of each construction of the class
        (``make_unique<Caller<pkg::srv::T>>(...)``, a derived template's base
        initialiser ``ClientBase<ServiceT>(...)`` followed to its own
        constructions), in call order; ``[]`` when none is found."""
        tps = unit_of(self.units, unit).tparams
        if param not in tps or depth > 4:
            return []
        i, out = tps.index(param), []
        for kind, callee, _args, _fkey, cunit, *_rest in self.calls:
            if kind == "member":  # a member initialised in a constructor: its declared type's arguments
                callee = unit_of(self.units, cunit).members.get(callee, callee)
            targs = split_template(callee.replace(" ", ""))[1] if kind in ("ctor", "member") else []
            if len(targs) <= i or self.match(callee, cunit) != unit:
                continue
            own = unit_of(self.units, cunit).tparams
            for x in self.template_types(cunit, targs[i], depth + 1) if targs[i] in own else [targs[i]]:
                if x not in out:
                    out.append(x)
        return out

    def members(self, r: dict[str, Any]) -> list[Endpoint]:
        """Pending endpoints of helper objects held as members or base classes (their
        class found in the program's declarations): made in a constructor's
        initialiser list, or by default where none initialises them; and of their
        methods' calls."""
        out: list[Endpoint] = []
        held = [(unit, m, ty, src, False) for unit, m, ty, src in r.get("member_decls", [])]
        held += [(unit, b, b, src, True) for unit, b, src in r.get("base_decls", [])]
        for unit, m, ty, src, base in held:
            if not self.runs(unit, None):
                continue
            last = split_template(m.replace(" ", ""))[0].split("::")[-1] if base else m
            inits: list[tuple[Any, ...] | None] = [c for c in self.calls if c[0] in ("member", "own-node")
                                                   and c[4] == unit and
                     (c[1] == m or base and split_template(c[1].replace(" ", ""))[0].split("::")[-1] == last)]
            for c in inits or [None]:
                if c is not None and c[0] == "own-node":  # a TransformListener given no node (said at it)
                    continue
                if c is not None and r.get("ros2") and cpp_helpers.own_node_of_values(self.aliases.get(ty, ty), c[2]):
                    # the same, initialised in a constructor of another file than the member's declaration
                    self.own_said.append(Note(c[5], cpp_helpers.OWN_NODE_SAID, "ROS-TF-OWN-NODE"))
                    continue
                args = c[2] if c else []
                at, fkey = (c[5], c[3]) if c else (src, None)
                for kind, nv, t, hv in self.helper(ty, args) or []:
                    out.append(Endpoint(kind, "", t, at, None, (), unit,
                                        (nv, hv, None, fkey, symbols.text(nv) or last, at), fkey))
        for kind0, callee, args, fkey, unit, at, *_kw in r.get("calls", []):
            # a helper made through a typedef another file declares (new Srv(nh), Srv s(nh))
            alias = self.aliases.get(callee) if kind0 == "ctor" and "::" not in callee else None
            if alias is None or not self.runs(unit, fkey):
                continue
            for kind, nv, t, hv in self.helper(alias, args) or []:
                out.append(Endpoint(kind, "", t, at, None, (), unit,
                                    (nv, hv, None, fkey, symbols.text(nv) or callee, at), fkey))
        for unit, m, meth, args, texts, src, fkey in r.get("member_calls", []):
            if not self.runs(unit, fkey):
                continue
            ty = unit_of(self.units, unit).members.get(m)
            for b in unit_of(self.units, unit).bases:
                cls = self.match(b, unit)
                ty = ty or (unit_of(self.units, cls).members.get(m) if cls else None)
            specs = cpp_helpers.method(ty, meth, args, [], lambda x: x, None, self.aliases) if ty else None
            for kind, nv, t, hv in specs or []:
                k = 1 if kind == "sub" and meth == "subscribe" else 0
                out.append(Endpoint(kind, "", t, src, None, (), unit,
                                    (nv, hv, None, fkey, texts[k] if k < len(texts) else m, src), fkey))
        return out

    def helper(self, ty: str, args: list[Any]) -> list[cpp_helpers.Spec] | None:
        """What a helper of type ``ty`` made with argument values ``args`` creates
        (``None``: no helper)."""
        head, targs = split_template(ty.replace(" ", ""))
        if "::" not in head and head in self.aliases:
            head, targs = split_template(self.aliases[head].replace(" ", ""))
        last = head.split("::")[-1]
        if last in _ACTIONLIB and targs:
            if not args:
                return []
            first = args[0]
            t = action_type_in(targs[0], self.using_ns)
            if len(args) >= 2 and first is not None and first[0] in ("nh", "field", "arg"):
                return [(_ACTIONLIB[last], args[1], t, first)]
            return [(_ACTIONLIB[last], first, t, None)]
        return cpp_helpers.constructed(ty, args, lambda x: x, False, self.aliases)
