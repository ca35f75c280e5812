"""The files of an Autoware System Designer design read one by one (docs/nodl.md, "Autoware System Designer"):
each ``*.node.yaml``, ``*.module.yaml`` and ``*.system.yaml`` as an :class:`Entity` (its data and the
location of every value), a node's ports as :class:`Port`, its processes as :class:`Process` with their
:class:`Trigger` conditions.  :mod:`rclverify.model.nodl.design` puts them together.

Every mistake is a :class:`~rclverify.lang.errors.RclError` (``E-design``) located at the offending key
or value, in the format's own terms: a format version not read (0.2.x and 0.3.x are), a ``name`` that is
not the file's name, a node derived from another (``base``), a port without ``name`` or with a
``message_type`` of another kind, a trigger or outcome naming no port or process, a monitoring field
that is no positive number, YAML that does not parse, a file leading outside the design folder.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
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

Path_ = tuple[Any, ...]


def fail(loc: ast.Loc, message: str) -> RclError:
    """The :class:`RclError` of one design mistake at ``loc`` (code ``E-design``), to raise."""
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


def design_files(root: Path) -> Iterator[tuple[Path, str]]:
    """The design files under ``root`` in name order, each with its name shown (``root`` as given, then the
    file's path under it)."""
    for path in sorted(root.rglob("*.yaml")):
        kind = path.name.rsplit(".", 2)[-2] if path.name.count(".") >= 2 else ""
        if kind in ("node", "module", "system"):
            yield path, (root / path.relative_to(root)).as_posix()


def read_entity(path: Path, shown: str, root: Path) -> Entity:
    """Read one design file (its format version, ``name`` matching the file name)."""
    if outside(root, path) is not None:
        raise fail(ast.Loc(shown, 1, 1), f"leads outside the design folder (to {outside(root, path)}); "
                                          "nothing is read from outside the folder given")
    try:
        data, locs = load_located(read_yaml_text(path, shown), shown)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = ast.Loc(shown, mark.line + 1, mark.column + 1) if mark is not None else ast.Loc(shown, 1, 1)
        raise fail(where, f"not YAML: {getattr(exc, 'problem', None) or exc}") from None
    kind = path.name.rsplit(".", 2)[-2]
    if not isinstance(data, dict):
        raise fail(ast.Loc(shown, 1, 1), f"a {kind} file is a mapping (autoware_system_design_format, name, ...)")
    ent = Entity(kind, "", shown, data, locs)
    version = str(data.get("autoware_system_design_format", ""))
    if not VERSION.match(version):
        raise fail(ent.loc("autoware_system_design_format"),
                    f"autoware_system_design_format {version or '(missing)'}: read are 0.2.x and 0.3.x")
    want = path.name[: -len(".yaml")]
    if data.get("name") != want:
        raise fail(ent.loc("name"), f"name {data.get('name')!r}: a {kind} file's name is its file name ({want!r})")
    if kind == "node" and "base" in data:
        raise fail(ent.loc("base", KEY), "a node derived from another (base, override, remove) is not read")
    ent.name = want.rsplit(".", 1)[0]
    return ent


def entries(ent: Entity, key: str) -> list[Any]:
    """The list ``ent`` holds at ``key`` (``[]`` when absent or null); raises :class:`RclError` when it is no list."""
    value = ent.data.get(key) or []
    if not isinstance(value, list):
        raise fail(ent.loc(key), f"{key} is a list")
    return value


def text_of(ent: Entity, item: Any, path: Path_, key: str) -> str:
    """``item[key]``, a non-empty text, of the mapping at ``path`` in ``ent``; raises :class:`RclError` there otherwise."""
    value = item.get(key) if isinstance(item, dict) else None
    if not isinstance(value, str) or not value:
        raise fail(ent.loc(*path), f"{'/'.join(str(p) for p in path)}: {key} is a non-empty text")
    return value


def ports_of(ent: Entity) -> list[Port]:
    """A node file's ports, list by list (:data:`PORT_LISTS`), in file order; raises :class:`RclError` at a port
    without ``name`` or ``message_type``, or whose type is not ``pkg/msg/Name`` (a topic) or ``pkg/srv|action/Name``."""
    out: list[Port] = []
    for key, role in PORT_LISTS.items():
        for i, item in enumerate(entries(ent, key)):
            name = text_of(ent, item, (key, i), "name")
            typ = text_of(ent, item, (key, i), "message_type")
            kinds = ("msg",) if role in ("publisher", "subscriber") else ("srv", "action")
            if typ.count("/") != 2 or typ.split("/")[1] not in kinds:
                raise fail(ent.loc(key, i, "message_type"), f"{key} {name}: message_type {typ!r} is "
                            f"pkg/{'|'.join(kinds)}/Name")
            qos = item.get("qos") or {}
            if not isinstance(qos, dict):
                raise fail(ent.loc(key, i, "qos"), f"{key} {name}: qos is a mapping (reliability, durability, ...)")
            glob = item.get("global")
            if glob is not None and (not isinstance(glob, str) or not glob.startswith("/")):
                raise fail(ent.loc(key, i, "global"), f"{key} {name}: global is an absolute ROS name (/tf)")
            pairs = tuple(sorted((k, str(v).lower()) for k, v in qos.items() if k in ("reliability", "durability")))
            out.append(Port(role, name, typ, pairs, glob, ent.loc(key, i)))
    return out


def _positive(v: Any) -> bool:
    """Whether ``v`` is a finite positive number (a YAML bool, ``.inf`` and ``.nan`` are not)."""
    return not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v) and v > 0


def _triggers(ent: Entity, cond: Any, path: Path_) -> Iterator[Trigger]:
    if not isinstance(cond, dict):
        raise fail(ent.loc(*path), "a trigger condition is a mapping (on_input, on_trigger, periodic, once, and, or)")
    for group in ("and", "or"):
        if group in cond:
            if not isinstance(cond[group], list):
                raise fail(ent.loc(*path, group), f"{group} is a list of trigger conditions")
            for j, sub in enumerate(cond[group]):
                yield from _triggers(ent, sub, path + (group, j))
            return
    kinds = [k for k in ("on_input", "on_trigger", "periodic", "once") if k in cond]
    if len(kinds) != 1:
        raise fail(ent.loc(*path), "a trigger condition has one of on_input, on_trigger, periodic, once (or and/or)")
    fields = []
    for name in ("timeout", "warn_rate", "error_rate"):
        if name in cond:
            v = cond[name]
            if not _positive(v):
                raise fail(ent.loc(*path, name), f"{name} is a positive number ({'s' if name == 'timeout' else 'Hz'})")
            fields.append((name, float(v), ent.loc(*path, name)))
    value = cond[kinds[0]]
    if kinds[0] == "periodic" and not _positive(value):
        raise fail(ent.loc(*path, "periodic"), "periodic is a positive rate in Hz")
    if kinds[0] in ("on_input", "on_trigger") and not (isinstance(value, str) and value) or \
            kinds[0] == "once" and value is not None and not isinstance(value, str):
        raise fail(ent.loc(*path, kinds[0]), f"{kinds[0]} names a {'process' if kinds[0] == 'on_trigger' else 'port'}")
    yield Trigger(kinds[0], value, ent.loc(*path, kinds[0]), tuple(fields))


def processes_of(ent: Entity, ports: list[Port]) -> list[Process]:
    """A node file's processes, each with every trigger condition (``and``/``or`` flattened) and outcome; raises
    :class:`RclError` at a condition or outcome of no known kind, one naming no port or process of ``ports``'s node,
    or a monitoring field that is no positive number."""
    out: list[Process] = []
    names = {p["name"] for p in entries(ent, "processes") if isinstance(p, dict) and isinstance(p.get("name"), str)}
    ins = {p.name for p in ports if p.role == "subscriber"}
    outs = {p.name for p in ports if p.role == "publisher"}
    for i, proc in enumerate(entries(ent, "processes")):
        name = text_of(ent, proc, ("processes", i), "name")
        for key in ("trigger_conditions", "outcomes"):
            if not isinstance(proc.get(key) or [], list):
                raise fail(ent.loc("processes", i, key), f"process {name}: {key} is a list")
        triggers = [t for j, c in enumerate(proc.get("trigger_conditions") or [])
                    for t in _triggers(ent, c, ("processes", i, "trigger_conditions", j))]
        outcomes = []
        for j, o in enumerate(proc.get("outcomes") or []):
            kind = next((k for k in ("to_output", "to_trigger", "terminal") if isinstance(o, dict) and k in o), None)
            if kind is None:
                raise fail(ent.loc("processes", i, "outcomes", j), "an outcome is to_output, to_trigger or terminal")
            if kind != "terminal" and not (isinstance(o[kind], str) and o[kind]):
                raise fail(ent.loc("processes", i, "outcomes", j, kind), f"{kind} names a "
                           f"{'port' if kind == 'to_output' else 'process'}")
            outcomes.append((kind, o[kind], ent.loc("processes", i, "outcomes", j, kind)))
        for t in triggers:
            bad = (t.kind in ("on_input",) or (t.kind == "once" and t.value is not None)) and t.value not in ins
            if bad or (t.kind == "on_trigger" and t.value not in names):
                raise fail(t.loc, f"process {name}: {t.kind} {t.value!r} names no "
                            f"{'process' if t.kind == 'on_trigger' else 'subscriber'} of {ent.name}")
        for kind, value, loc in outcomes:
            if (kind == "to_output" and value not in outs) or (kind == "to_trigger" and value not in names):
                raise fail(loc, f"process {name}: {kind} {value!r} names no "
                            f"{'publisher' if kind == 'to_output' else 'process'} of {ent.name}")
        out.append(Process(name, ent.loc("processes", i), tuple(triggers), tuple(outcomes)))
    return out


__all__ = ["Entity", "PORT_LISTS", "Port", "Process", "Trigger", "VERSION", "design_files", "entries", "fail",
           "ports_of", "processes_of", "read_entity", "text_of"]
