"""An Autoware System Designer design read into one flat architecture (docs/nodl.md, "Autoware System Designer").

A design is a folder of YAML files in the designer's ``autoware_system_design_format``
(0.2.x and 0.3.x are read): ``*.node.yaml`` (a node's ports and its
``processes``), ``*.module.yaml`` (instances of nodes and modules, boundary
ports, ``connections``) and ``*.system.yaml`` (``components`` and their
``connections``).  :func:`read_design` reads every such file under the folder
(nothing outside it: a link leading out is a located error), takes the
system (the one there is, or the one named), and flattens it: every node
reached through the components and the modules' instances is one
:class:`DesignNode`, named by its instance path joined with ``_``
(``object_recognition`` / ``tracker`` is ``object_recognition_tracker``), and
every pair of a publisher and a subscriber (a server and a client) that
the connections join, through any number of module boundaries, is one
:class:`Wire`; so is a reader wired to nothing whose name is a writer's (ROS joins two ends of
one name: a ``global`` ``/tf``).

Topic names: a publisher's is its ``global`` name, else the component's
``path`` (or ``/<component>``) followed by the instance names and the port
name; a subscriber's is its publisher's, else its ``global`` name, else its
own path as for a publisher (a port wired to nothing: an input from outside
the design).  These are rclverify's names, not the designer's launch names
(its ``remap_target`` is the node's internal name and is not read).

Every mistake is a :class:`~rclverify.lang.errors.RclError` located at the
file, line and column of the offending key or value, in the format's own
terms (``E-design``).  Not read: modes' ``override``/``remove``,
``parameter_set``, ``node_groups``, ``variables``, parameters, ``launch``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rclverify.lang import ast
from rclverify.model.nodl.design_read import (PORT_LISTS, Entity, Port, Process, design_files, entries, fail, ports_of,
                                             processes_of, read_entity, text_of)

#: An RCL node name made of instance names.
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
#: The roles of one end of a wire: the writer's and the reader's.
WRITER = {"publisher": "subscriber", "server": "client"}


@dataclass
class DesignNode:
    """One node instance of the flattened system: its RCL ``name``, the ``entity`` it instantiates,
    its instance ``path`` (component, instance names), its namespace ``ns``, ports and processes."""

    name: str
    entity: Entity
    path: tuple[str, ...]
    ns: str
    ports: list[Port] = field(default_factory=list)
    processes: list[Process] = field(default_factory=list)
    topics: dict[tuple[str, str], str] = field(default_factory=dict)

    def own_topic(self, port: Port) -> str:
        """The name ``port`` has by itself: its ``global`` name, else its path (module docstring)."""
        return port.global_name or f"{self.ns.rstrip('/')}/{'/'.join(self.path[1:] + (port.name,))}"


@dataclass(frozen=True)
class Wire:
    """A writer's port (publisher or server) joined to a reader's (subscriber or client) by ``loc``'s connection."""

    writer: str
    writer_port: str
    reader: str
    reader_port: str
    role: str
    loc: ast.Loc


@dataclass
class Design:
    """A flattened design: the system's ``name``, its file, the nodes (by RCL name) and the wires."""

    name: str
    file: str
    nodes: dict[str, DesignNode]
    wires: list[Wire]


class _Flatten:
    """The system's instance tree walked once: nodes made, ports joined (a union-find over port keys)."""

    def __init__(self, entities: dict[str, Entity]) -> None:
        self.entities = entities
        self.nodes: dict[str, DesignNode] = {}
        self.parent: dict[Any, Any] = {}
        self.join_loc: dict[Any, ast.Loc] = {}
        self.leaf: dict[Any, tuple[DesignNode, Port]] = {}

    def find(self, k: Any) -> Any:
        while self.parent.setdefault(k, k) != k:
            k = self.parent[k]
        return k

    def entity(self, ref: Any, loc: ast.Loc) -> Entity:
        if not isinstance(ref, str) or ref not in self.entities:
            raise fail(loc, f"entity {ref!r} is no node or module of the design folder "
                             f"(known: {', '.join(sorted(self.entities)) or 'none'})")
        return self.entities[ref]

    def place(self, ent: Entity, path: tuple[str, ...], ns: str, loc: ast.Loc, within: tuple[str, ...] = ()) -> None:
        """Instantiate ``ent`` at ``path`` (inside the modules ``within``): a node is made, a module's instances
        placed and its connections joined; a module inside itself is a located error."""
        key = f"{ent.name}.{ent.kind}"
        if key in within:
            raise fail(loc, f"{key} is an instance of itself (through {' -> '.join(within + (key,))})")
        if ent.kind == "node":
            name = "_".join(path)
            if not _IDENT.match(name) or name in self.nodes:
                raise fail(loc, f"instance {'/'.join(path)}: its node name {name!r} is "
                                 f"{'taken by another instance' if name in self.nodes else 'no RCL name'}")
            node = DesignNode(name, ent, path, ns)
            node.ports = ports_of(ent)
            node.processes = processes_of(ent, node.ports)
            self.nodes[name] = node
            for p in node.ports:
                self.leaf[(path, p.role, p.name)] = (node, p)
            return
        if ent.kind != "module":
            raise fail(loc, f"entity {ent.name}.{ent.kind}: an instance is a node or a module")
        for i, inst in enumerate(entries(ent, "instances")):
            name = text_of(ent, inst, ("instances", i), "name")
            self.place(self.entity(inst.get("entity"), ent.loc("instances", i, "entity")), path + (name,), ns,
                       ent.loc("instances", i), within + (key,))
        self.connect(ent, path)

    def port_names(self, path: tuple[str, ...], role: str, ent: Entity | None) -> list[str]:
        """The port names of ``role`` at ``path``: an instance's (its entity's list) or a module's boundary."""
        if ent is None:
            return []
        key = {v: k for k, v in PORT_LISTS.items()}[role]
        return [str(p.get("name")) for p in entries(ent, key) if isinstance(p, dict)]

    def end(self, ent: Entity, path: tuple[str, ...], text: Any, loc: ast.Loc,
            children: dict[str, Entity | None]) -> tuple[tuple[str, ...], str, str, Entity | None]:
        """One end of a connection: (instance path, role, port name or ``*``, the entity whose ports it names)."""
        parts = text.split(".", 2) if isinstance(text, str) else []
        if len(parts) >= 2 and parts[0] in PORT_LISTS.values():
            if ent.kind == "system":
                raise fail(loc, f"{text!r}: a system has no ports of its own; write component.{parts[0]}.port")
            return path, parts[0], ".".join(parts[1:]), ent
        if len(parts) == 3 and parts[1] in PORT_LISTS.values() and parts[0] in children:
            return path + (parts[0],), parts[1], parts[2], children[parts[0]]
        raise fail(loc, f"{text!r} is no port path (role.port, or instance.role.port with an instance of "
                         f"{ent.name}: {', '.join(sorted(children)) or 'none'})")

    def connect(self, ent: Entity, path: tuple[str, ...]) -> None:
        key = "instances" if ent.kind == "module" else "components"
        children = {str(c.get("name")): self.entities.get(str(c.get("entity"))) for c in entries(ent, key)
                    if isinstance(c, dict)}
        for i, pair in enumerate(entries(ent, "connections")):
            loc = ent.loc("connections", i)
            if not isinstance(pair, list) or len(pair) != 2:
                raise fail(loc, "a connection is a pair of port paths")
            a, b = (self.end(ent, path, pair[j], ent.loc("connections", i, j), children) for j in (0, 1))
            names = [(a[2], b[2])]
            if "*" in (a[2], b[2]):
                if (a[2], b[2]) != ("*", "*"):
                    raise fail(loc, "a wildcard connection has * on both ends")
                mine = set(self.port_names(b[0], b[1], b[3]))
                names = [(n, n) for n in self.port_names(a[0], a[1], a[3]) if n in mine]
            for na, nb in names:
                for side, n in ((a, na), (b, nb)):
                    if side[3] is not None and n not in self.port_names(side[0], side[1], side[3]):
                        raise fail(loc, f"{'/'.join(side[0]) or ent.name} has no {side[1]} {n!r}")
                ka, kb = (a[0], a[1], na), (b[0], b[1], nb)
                self.parent[self.find(ka)] = self.find(kb)
                self.join_loc.setdefault(ka, loc)
                self.join_loc.setdefault(kb, loc)

    def wires(self) -> list[Wire]:
        """Every writer joined to a reader, each reader's topic set from its writer's."""
        nets: dict[Any, list[Any]] = {}
        for k in self.leaf:
            nets.setdefault(self.find(k), []).append(k)
        out: list[Wire] = []
        for keys in nets.values():
            for role, reader_role in WRITER.items():
                writers = [self.leaf[k] for k in sorted(keys) if k[1] == role]
                readers = [self.leaf[k] for k in sorted(keys) if k[1] == reader_role]
                names = sorted({w.own_topic(p) for w, p in writers})
                if len(names) > 1:
                    raise fail(self.join_loc.get(keys[0], writers[0][1].loc), f"{len(writers)} {role}s of "
                                f"different names ({', '.join(names)}) are joined into one {reader_role}'s input")
                for w, wp in writers:
                    w.topics[(wp.role, wp.name)] = w.own_topic(wp)
                    for r, rp in readers:
                        r.topics[(rp.role, rp.name)] = names[0]
                        loc = self.join_loc.get((r.path, rp.role, rp.name), rp.loc)
                        out.append(Wire(w.name, wp.name, r.name, rp.name, role, loc))
        for node in self.nodes.values():
            for p in node.ports:
                node.topics.setdefault((p.role, p.name), node.own_topic(p))
        out += self.by_name(out)
        return sorted(out, key=lambda w: (w.writer, w.writer_port, w.reader, w.reader_port))


    def by_name(self, wired: list[Wire]) -> list[Wire]:
        """The reader ports no connection wires whose name is a writer's topic: ROS joins them by that name
        (a ``global`` name two nodes share, ``/tf``), so they are wires too, located at the reader's port."""
        fed = {(w.reader, w.reader_port, w.role) for w in wired}
        writers: dict[tuple[str, str], list[tuple[DesignNode, Port]]] = {}
        for node in self.nodes.values():
            for p in node.ports:
                if p.role in WRITER:
                    writers.setdefault((p.role, node.topics[(p.role, p.name)]), []).append((node, p))
        out = []
        for node in self.nodes.values():
            for p in node.ports:
                role = next((w for w, r in WRITER.items() if r == p.role), None)
                if role is None or (node.name, p.name, role) in fed:
                    continue
                for w, wp in writers.get((role, node.topics[(p.role, p.name)]), []):
                    if w is not node:
                        out.append(Wire(w.name, wp.name, node.name, p.name, role, p.loc))
        return out


def read_design(root: Path, system: str | None = None) -> Design:
    """The design under folder ``root`` flattened from its system (``system``: its name, needed when the folder
    holds several).  Raises :class:`RclError` (``E-design``) located at the mistake (module docstring)."""
    entities: dict[str, Entity] = {}
    systems: list[Entity] = []
    for path, shown in design_files(root):
        ent = read_entity(path, shown, root)
        key = f"{ent.name}.{ent.kind}"
        if key in entities or any(s.name == ent.name for s in systems if ent.kind == "system"):
            raise fail(ent.loc("name"), f"{key} is defined twice in the design folder")
        if ent.kind == "system":
            systems.append(ent)
        else:
            entities[key] = ent
    chosen = [s for s in systems if system is None or s.name == system]
    if len(chosen) != 1:
        have = ", ".join(s.name for s in systems) or "none"
        raise fail(ast.Loc(root.as_posix(), 1, 1), f"{'no system named ' + repr(system) if system else 'the design needs one *.system.yaml'}"
                    f" (systems in the folder: {have}{'; name one with --system' if len(chosen) > 1 else ''})")
    sys_ent = chosen[0]
    flat = _Flatten(entities)
    for i, comp in enumerate(entries(sys_ent, "components")):
        name = text_of(sys_ent, comp, ("components", i), "name")
        ns = comp.get("path") or comp.get("namespace") or f"/{name}"
        if not isinstance(ns, str) or not ns.startswith("/"):
            raise fail(sys_ent.loc("components", i, "path"), f"component {name}: its path is an absolute ROS namespace")
        flat.place(flat.entity(comp.get("entity"), sys_ent.loc("components", i, "entity")), (name,), ns,
                   sys_ent.loc("components", i))
    flat.connect(sys_ent, ())
    return Design(sys_ent.name, sys_ent.file, flat.nodes, flat.wires())


__all__ = ["Design", "DesignNode", "WRITER", "Wire", "read_design"]
