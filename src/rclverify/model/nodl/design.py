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
from typing import Any, Iterator

import yaml

from rclverify.core.within import outside
from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.model.plan.yamlguard import KEY, load_located, read_yaml_text

#: The format versions read: major 0, minor 2 or 3 (the designer's schemas 0.2.1 to 0.3.2).
VERSION = re.compile(r"^0\.[23](\.\d+)?$")
#: The port lists of a node, each with the role a connection's port path names it by.
PORT_LISTS = {"subscribers": "subscriber", "publishers": "publisher", "servers": "server", "clients": "client"}
#: An RCL node name made of instance names.
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
#: The roles of one end of a wire: the writer's and the reader's.
WRITER = {"publisher": "subscriber", "server": "client"}

Path_ = tuple[Any, ...]


def _fail(loc: ast.Loc, message: str) -> RclError:
    return RclError([error(loc, message, "E-design")])


@dataclass(frozen=True)
class Port:
    """A node's port: ``role`` (publisher, subscriber, server, client), ``name`` as written, its
    ``type`` (``pkg/msg/Name``, ``pkg/srv/Name``, ``pkg/action/Name``), its ``qos``
    (``reliability``, ``durability`` as written, lower case) and ``global`` name, ``loc`` its entry."""

    role: str
    name: str
    type: str
    qos: tuple[tuple[str, str], ...]
    global_name: str | None
    loc: ast.Loc


@dataclass(frozen=True)
class Trigger:
    """One condition of a process: ``kind`` (``on_input``, ``on_trigger``, ``periodic``, ``once``),
    its ``value`` (a port, a process, a rate in Hz, or ``None``), the monitoring fields given
    (``timeout`` in s, ``warn_rate`` and ``error_rate`` in Hz, as written) with their locations."""

    kind: str
    value: Any
    loc: ast.Loc
    fields: tuple[tuple[str, float, ast.Loc], ...] = ()


@dataclass(frozen=True)
class Process:
    """A process: ``name``, its ``triggers`` (``and``/``or`` flattened: every condition), its
    ``outcomes`` as ``(kind, value, loc)`` (``to_output``, ``to_trigger``, ``terminal``)."""

    name: str
    loc: ast.Loc
    triggers: tuple[Trigger, ...]
    outcomes: tuple[tuple[str, Any, ast.Loc], ...]


@dataclass
class Entity:
    """One design file: ``kind`` (node, module, system), ``name`` (``Tracker``), its data and locations."""

    kind: str
    name: str
    file: str
    data: dict[str, Any]
    locs: dict[Path_, ast.Loc]

    def loc(self, *path: Any) -> ast.Loc:
        """The location of the value at ``path`` (the nearest enclosing one written)."""
        p: Path_ = tuple(path)
        while p and p not in self.locs:
            p = p[:-1]
        return self.locs.get(p, ast.Loc(self.file, 1, 1))


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


def _files(root: Path) -> Iterator[tuple[Path, str]]:
    """The design files under ``root`` in name order, each with its name shown (``root`` as given, then the
    file's path under it)."""
    for path in sorted(root.rglob("*.yaml")):
        kind = path.name.rsplit(".", 2)[-2] if path.name.count(".") >= 2 else ""
        if kind in ("node", "module", "system"):
            yield path, (root / path.relative_to(root)).as_posix()


def _entity(path: Path, shown: str, root: Path) -> Entity:
    """Read one design file (its format version, ``name`` matching the file name)."""
    if outside(root, path) is not None:
        raise _fail(ast.Loc(shown, 1, 1), f"leads outside the design folder (to {outside(root, path)}); "
                                          "nothing is read from outside the folder given")
    try:
        data, locs = load_located(read_yaml_text(path, shown), shown)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = ast.Loc(shown, mark.line + 1, mark.column + 1) if mark is not None else ast.Loc(shown, 1, 1)
        raise _fail(where, f"not YAML: {getattr(exc, 'problem', None) or exc}") from None
    kind = path.name.rsplit(".", 2)[-2]
    if not isinstance(data, dict):
        raise _fail(ast.Loc(shown, 1, 1), f"a {kind} file is a mapping (autoware_system_design_format, name, ...)")
    ent = Entity(kind, "", shown, data, locs)
    version = str(data.get("autoware_system_design_format", ""))
    if not VERSION.match(version):
        raise _fail(ent.loc("autoware_system_design_format"),
                    f"autoware_system_design_format {version or '(missing)'}: read are 0.2.x and 0.3.x")
    want = path.name[: -len(".yaml")]
    if data.get("name") != want:
        raise _fail(ent.loc("name"), f"name {data.get('name')!r}: a {kind} file's name is its file name ({want!r})")
    if kind == "node" and "base" in data:
        raise _fail(ent.loc("base", KEY), "a node derived from another (base, override, remove) is not read")
    ent.name = want.rsplit(".", 1)[0]
    return ent


def _list(ent: Entity, key: str) -> list[Any]:
    value = ent.data.get(key) or []
    if not isinstance(value, list):
        raise _fail(ent.loc(key), f"{key} is a list")
    return value


def _text(ent: Entity, item: Any, path: Path_, key: str) -> str:
    value = item.get(key) if isinstance(item, dict) else None
    if not isinstance(value, str) or not value:
        raise _fail(ent.loc(*path), f"{'/'.join(str(p) for p in path)}: {key} is a non-empty text")
    return value


def _ports(ent: Entity) -> list[Port]:
    out: list[Port] = []
    for key, role in PORT_LISTS.items():
        for i, item in enumerate(_list(ent, key)):
            name = _text(ent, item, (key, i), "name")
            typ = _text(ent, item, (key, i), "message_type")
            kinds = ("msg",) if role in ("publisher", "subscriber") else ("srv", "action")
            if typ.count("/") != 2 or typ.split("/")[1] not in kinds:
                raise _fail(ent.loc(key, i, "message_type"), f"{key} {name}: message_type {typ!r} is "
                            f"pkg/{'|'.join(kinds)}/Name")
            qos = item.get("qos") or {}
            pairs = tuple(sorted((k, str(v).lower()) for k, v in qos.items() if k in ("reliability", "durability")))
            out.append(Port(role, name, typ, pairs, item.get("global"), ent.loc(key, i)))
    return out


def _triggers(ent: Entity, cond: Any, path: Path_) -> Iterator[Trigger]:
    if not isinstance(cond, dict):
        raise _fail(ent.loc(*path), "a trigger condition is a mapping (on_input, on_trigger, periodic, once, and, or)")
    for group in ("and", "or"):
        if group in cond:
            for j, sub in enumerate(cond[group] or []):
                yield from _triggers(ent, sub, path + (group, j))
            return
    kinds = [k for k in ("on_input", "on_trigger", "periodic", "once") if k in cond]
    if len(kinds) != 1:
        raise _fail(ent.loc(*path), "a trigger condition has one of on_input, on_trigger, periodic, once (or and/or)")
    fields = []
    for name in ("timeout", "warn_rate", "error_rate"):
        if name in cond:
            v = cond[name]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v <= 0:
                raise _fail(ent.loc(*path, name), f"{name} is a positive number ({'s' if name == 'timeout' else 'Hz'})")
            fields.append((name, float(v), ent.loc(*path, name)))
    value = cond[kinds[0]]
    if kinds[0] == "periodic" and (isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0):
        raise _fail(ent.loc(*path, "periodic"), "periodic is a positive rate in Hz")
    yield Trigger(kinds[0], value, ent.loc(*path, kinds[0]), tuple(fields))


def _processes(ent: Entity, ports: list[Port]) -> list[Process]:
    out: list[Process] = []
    names = {p.get("name") for p in _list(ent, "processes") if isinstance(p, dict)}
    ins = {p.name for p in ports if p.role == "subscriber"}
    outs = {p.name for p in ports if p.role == "publisher"}
    for i, proc in enumerate(_list(ent, "processes")):
        name = _text(ent, proc, ("processes", i), "name")
        triggers = [t for j, c in enumerate(proc.get("trigger_conditions") or [])
                    for t in _triggers(ent, c, ("processes", i, "trigger_conditions", j))]
        outcomes = []
        for j, o in enumerate(proc.get("outcomes") or []):
            kind = next((k for k in ("to_output", "to_trigger", "terminal") if isinstance(o, dict) and k in o), None)
            if kind is None:
                raise _fail(ent.loc("processes", i, "outcomes", j), "an outcome is to_output, to_trigger or terminal")
            outcomes.append((kind, o[kind], ent.loc("processes", i, "outcomes", j, kind)))
        for t in triggers:
            bad = (t.kind in ("on_input",) or (t.kind == "once" and t.value is not None)) and t.value not in ins
            if bad or (t.kind == "on_trigger" and t.value not in names):
                raise _fail(t.loc, f"process {name}: {t.kind} {t.value!r} names no "
                            f"{'process' if t.kind == 'on_trigger' else 'subscriber'} of {ent.name}")
        for kind, value, loc in outcomes:
            if (kind == "to_output" and value not in outs) or (kind == "to_trigger" and value not in names):
                raise _fail(loc, f"process {name}: {kind} {value!r} names no "
                            f"{'publisher' if kind == 'to_output' else 'process'} of {ent.name}")
        out.append(Process(name, ent.loc("processes", i), tuple(triggers), tuple(outcomes)))
    return out


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
            raise _fail(loc, f"entity {ref!r} is no node or module of the design folder "
                             f"(known: {', '.join(sorted(self.entities)) or 'none'})")
        return self.entities[ref]

    def place(self, ent: Entity, path: tuple[str, ...], ns: str, loc: ast.Loc) -> None:
        """Instantiate ``ent`` at ``path``: a node is made, a module's instances placed and its connections joined."""
        if ent.kind == "node":
            name = "_".join(path)
            if not _IDENT.match(name) or name in self.nodes:
                raise _fail(loc, f"instance {'/'.join(path)}: its node name {name!r} is "
                                 f"{'taken by another instance' if name in self.nodes else 'no RCL name'}")
            node = DesignNode(name, ent, path, ns)
            node.ports = _ports(ent)
            node.processes = _processes(ent, node.ports)
            self.nodes[name] = node
            for p in node.ports:
                self.leaf[(path, p.role, p.name)] = (node, p)
            return
        if ent.kind != "module":
            raise _fail(loc, f"entity {ent.name}.{ent.kind}: an instance is a node or a module")
        for i, inst in enumerate(_list(ent, "instances")):
            name = _text(ent, inst, ("instances", i), "name")
            self.place(self.entity(inst.get("entity"), ent.loc("instances", i, "entity")), path + (name,), ns,
                       ent.loc("instances", i))
        self.connect(ent, path)

    def ports_of(self, path: tuple[str, ...], role: str, ent: Entity | None) -> list[str]:
        """The port names of ``role`` at ``path``: an instance's (its entity's list) or a module's boundary."""
        if ent is None:
            return []
        key = {v: k for k, v in PORT_LISTS.items()}[role]
        return [str(p.get("name")) for p in _list(ent, key) if isinstance(p, dict)]

    def end(self, ent: Entity, path: tuple[str, ...], text: Any, loc: ast.Loc,
            children: dict[str, Entity | None]) -> tuple[tuple[str, ...], str, str, Entity | None]:
        """One end of a connection: (instance path, role, port name or ``*``, the entity whose ports it names)."""
        parts = text.split(".", 2) if isinstance(text, str) else []
        if len(parts) >= 2 and parts[0] in PORT_LISTS.values():
            if ent.kind == "system":
                raise _fail(loc, f"{text!r}: a system has no ports of its own; write component.{parts[0]}.port")
            return path, parts[0], ".".join(parts[1:]), ent
        if len(parts) == 3 and parts[1] in PORT_LISTS.values() and parts[0] in children:
            return path + (parts[0],), parts[1], parts[2], children[parts[0]]
        raise _fail(loc, f"{text!r} is no port path (role.port, or instance.role.port with an instance of "
                         f"{ent.name}: {', '.join(sorted(children)) or 'none'})")

    def connect(self, ent: Entity, path: tuple[str, ...]) -> None:
        key = "instances" if ent.kind == "module" else "components"
        children = {str(c.get("name")): self.entities.get(str(c.get("entity"))) for c in _list(ent, key)
                    if isinstance(c, dict)}
        for i, pair in enumerate(_list(ent, "connections")):
            loc = ent.loc("connections", i)
            if not isinstance(pair, list) or len(pair) != 2:
                raise _fail(loc, "a connection is a pair of port paths")
            a, b = (self.end(ent, path, pair[j], ent.loc("connections", i, j), children) for j in (0, 1))
            names = [(a[2], b[2])]
            if "*" in (a[2], b[2]):
                if (a[2], b[2]) != ("*", "*"):
                    raise _fail(loc, "a wildcard connection has * on both ends")
                mine = set(self.ports_of(b[0], b[1], b[3]))
                names = [(n, n) for n in self.ports_of(a[0], a[1], a[3]) if n in mine]
            for na, nb in names:
                for side, n in ((a, na), (b, nb)):
                    if side[3] is not None and n not in self.ports_of(side[0], side[1], side[3]):
                        raise _fail(loc, f"{'/'.join(side[0]) or ent.name} has no {side[1]} {n!r}")
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
                    raise _fail(self.join_loc.get(keys[0], writers[0][1].loc), f"{len(writers)} {role}s of "
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
    for path, shown in _files(root):
        ent = _entity(path, shown, root)
        key = f"{ent.name}.{ent.kind}"
        if key in entities or any(s.name == ent.name for s in systems if ent.kind == "system"):
            raise _fail(ent.loc("name"), f"{key} is defined twice in the design folder")
        if ent.kind == "system":
            systems.append(ent)
        else:
            entities[key] = ent
    chosen = [s for s in systems if system is None or s.name == system]
    if len(chosen) != 1:
        have = ", ".join(s.name for s in systems) or "none"
        raise _fail(ast.Loc(root.as_posix(), 1, 1), f"{'no system named ' + repr(system) if system else 'the design needs one *.system.yaml'}"
                    f" (systems in the folder: {have}{'; name one with --system' if len(chosen) > 1 else ''})")
    sys_ent = chosen[0]
    flat = _Flatten(entities)
    for i, comp in enumerate(_list(sys_ent, "components")):
        name = _text(sys_ent, comp, ("components", i), "name")
        ns = comp.get("path") or comp.get("namespace") or f"/{name}"
        if not isinstance(ns, str) or not ns.startswith("/"):
            raise _fail(sys_ent.loc("components", i, "path"), f"component {name}: its path is an absolute ROS namespace")
        flat.place(flat.entity(comp.get("entity"), sys_ent.loc("components", i, "entity")), (name,), ns,
                   sys_ent.loc("components", i))
    flat.connect(sys_ent, ())
    return Design(sys_ent.name, sys_ent.file, flat.nodes, flat.wires())


__all__ = ["Design", "DesignNode", "Entity", "PORT_LISTS", "Port", "Process", "Trigger", "Wire", "read_design"]
