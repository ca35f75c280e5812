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

The program's index (its merged records and the lookups in them) is
:mod:`link_index`'s, what runs what :mod:`link_reach`'s; the value
evaluation :mod:`link_values`', :mod:`link_members`' and :mod:`link_types`'.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Callable

from rclverify.ros.extract import emit, names, symbols
from rclverify.ros.extract.cpp_types import alias_index
from rclverify.ros.extract.model import Endpoint, Note, Src
from rclverify.ros.extract.link_members import LinkMembers
from rclverify.ros.extract.link_reach import LinkReach
from rclverify.ros.extract.link_returns import Returns
from rclverify.ros.extract.link_types import Instances, is_template_param
from rclverify.ros.extract.link_values import MAX_DEPTH, MAX_VALUES, Values, _homes
from rclverify.ros.extract.programs import PackageCode, Program
from rclverify.ros.extract.unit_names import canonical
from rclverify.ros.extract.link_units import UnitInfo, unit_of

__all__ = ["Linked", "Linker", "MAX_DEPTH", "MAX_VALUES"]


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


class Linker(LinkReach, LinkMembers, Values, Returns, Instances):
    """Link one program of a package (see the module docstring); ``known(t)`` says
    whether the scan's type table defines message type ``t``."""

    def __init__(self, prog: Program, code: PackageCode, known: Callable[[str], bool]) -> None:
        self.prog, self.code, self.known = prog, code, known
        self.recs = canonical({f: code.records[f] for f in prog.files if f in code.records})
        self.fns: dict[str, tuple[str, list[str], list[str], list[Any]]] = {}
        self.units: dict[str, UnitInfo] = {}
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
                        or unit_of(self.units, unit).tparams)
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
