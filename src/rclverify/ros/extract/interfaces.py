"""Message, service and action definitions through rosbags' type system.

* workspace packages: ``msg/*.msg``, ``srv/*.srv`` (``Name_Request`` /
  ``Name_Response``), ``action/*.action`` (``Name_Goal`` / ``_Result`` /
  ``_Feedback``) and ``msg|srv|action/*.idl``; a field type without a
  package resolves in its own package (ROS 1 and 2 ``.msg`` rule);
* standard packages (std_msgs, geometry_msgs, sensor_msgs, nav_msgs ...):
  from Debian's ``ros-*-msgs`` packages (``/usr/share/<pkg>/msg``) where
  installed, otherwise from rosbags' own store (ROS 2 Humble's definitions);
* types of an *absent* interface package (:meth:`TypeTable.mark_absent`: in
  neither the scanned tree nor an installed ROS, ``ros/graph/absent.py``):
  known by name only, with origin :data:`ABSENT` and no field read.

Types are named ``pkg/msg/Type`` (rosbags' form).  A field is
``(name, (nodetype, detail))`` as rosbags gives it: nodetype 1 base
(``('float32', bound)``), 2 named message, 3 fixed array ``(elem, n)``,
4 sequence ``(elem, bound)``.
"""
from __future__ import annotations

from rclverify.ros.extract import safefs

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable

from rclverify.ros.extract.cache import ParseCache
from rclverify.ros.extract.model import Note, Src
from rclverify.ros.extract.cmake import expand
from rclverify.ros.extract.shapes import FieldJson, TypeField, TypeJson

if TYPE_CHECKING:
    from rosbags.interfaces.typing import Typesdict

DEBIAN_SHARE = Path("/usr/share")


def ament_prefixes() -> list[Path]:
    """The install prefixes of a sourced ROS 2 (``AMENT_PREFIX_PATH``, in order;
    ament_index's search path), those that exist."""
    return [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p and Path(p).is_dir()]
BASE_TYPES = {"bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
              "uint64", "float32", "float64", "string", "wstring", "time", "duration", "octet"}
_COMMENT = re.compile(r"#.*$")
#: the origin of a type known by name only: its package is absent (docs/ros.md, "Absent interface packages")
ABSENT = "absent"


@dataclass
class TypeInfo:
    """One message type: constants ``[(name, type, value)]``, fields
    ``[(name, desc)]``, where it came from (``workspace``, ``debian``,
    ``rosbags``) and, for workspace files, the file shown and each field's line."""

    consts: list[tuple[str, str, Any]]
    fields: list[tuple[str, Any]]
    origin: str
    file: str | None = None
    lines: dict[str, int] = field(default_factory=dict)

    def to_json(self) -> TypeJson:
        return {
            "origin": self.origin, "file": self.file,
            "fields": [_field(n, d, self.lines.get(n)) for n, d in self.fields],
            "constants": [{"name": n, "type": t, "value": v if isinstance(v, (int, float, str, bool)) else str(v)}
                          for n, t, v in self.consts],
        }


def _field(name: str, desc: Any, line: int | None) -> TypeField:
    """One field's JSON: its name, :func:`describe`'s keys, and its line when known."""
    d = describe(desc)
    out: TypeField = {"name": name, "type": d["type"], "array": d["array"]}
    if line is not None:
        out["line"] = line
    return out


def describe(desc: Any) -> FieldJson:
    """A rosbags field description as JSON: ``{"type": ..., "array": None|"[]"|"[N]"|"[<=N]"}``."""
    kind, detail = desc
    kind = int(kind)
    if kind == 1:
        base, bound = detail
        return {"type": base if not bound else f"{base}<={bound}", "array": None}
    if kind == 2:
        return {"type": str(detail), "array": None}
    inner, n = detail
    elem = describe(inner)
    return {"type": elem["type"], "array": f"[{n}]" if kind == 3 else (f"[<={n}]" if n else "[]")}


def elem_type(desc: Any) -> tuple[str, bool]:
    """``(element type name, is_array)`` of a field description."""
    d = describe(desc)
    return d["type"].split("<=")[0], d["array"] is not None


def _field_lines(text: str) -> dict[str, int]:
    out: dict[str, int] = {}
    for k, raw in enumerate(text.splitlines(), 1):
        line = _COMMENT.sub("", raw).strip()
        if not line or line.startswith("---"):
            continue
        toks = line.split()
        if len(toks) >= 2:
            name = toks[1].split("=")[0]
            out.setdefault(name, k)
    return out


def generated_interfaces(root: Path, pkg: str) -> list[Path]:
    """The interface files ``rosidl_generate_interfaces(${PROJECT_NAME} ...)`` of
    the package's ``CMakeLists.txt`` names (variables and ``foreach`` expanded,
    :func:`cmake.expand`), those under ``root`` that exist; ``[]`` when the
    file is absent or unreadable.  Source: rosidl_cmake's
    ``rosidl_generate_interfaces`` (its arguments after the target are
    interface files relative to the package, up to the first keyword)."""
    try:
        text = safefs.read_bytes(root / "CMakeLists.txt").decode("utf-8", errors="replace")
    except OSError:
        return []
    out: list[Path] = []
    for name, args, _line in expand(text, pkg):
        if name.lower() != "rosidl_generate_interfaces":
            continue
        for a in args[1:]:
            if a.isupper() and a.isalpha() or a.startswith(("ADD_LINTER_TESTS", "DEPENDENCIES", "LIBRARY_NAME",
                                                            "SKIP_INSTALL", "SKIP_GROUP_MEMBERSHIP_CHECK")):
                break
            base, sep, rel = a.partition(":")  # rosidl's "base_dir:relative/file.msg" form
            f = root / (Path(base) / rel if sep else Path(a))
            if f.suffix in (".msg", ".srv", ".action", ".idl") and f.is_file() and \
                    f.resolve().is_relative_to(root.resolve()) and f.resolve() not in {x.resolve() for x in out}:
                out.append(f)
    return out


def _parse_one(kind: str, text: str, name: str) -> Typesdict:
    from rosbags.typesys import get_types_from_idl, get_types_from_msg  # deferred: start-up (loads rosbags and more only when called)
    if kind == "idl":
        return dict(get_types_from_idl(text))
    if kind == "msg":
        return dict(get_types_from_msg(text, name))
    pkg, _, base = name.split("/")
    parts = re.split(r"^---\s*$", text, flags=re.M)
    suffixes = ("_Request", "_Response") if kind == "srv" else ("_Goal", "_Result", "_Feedback")
    if len(parts) != len(suffixes):
        raise ValueError(f"a .{kind} file has {len(suffixes)} parts separated by '---', this one has {len(parts)}")
    out: Typesdict = {}
    for part, suf in zip(parts, suffixes):
        # parsed as pkg/msg/...: a field type without a package is pkg/msg/T, the
        # same package's message (rosidl's rule), never pkg/srv/msg/T
        for k, v in get_types_from_msg(part, f"{pkg}/msg/{base}{suf}").items():
            out[k.replace(f"{pkg}/msg/{base}{suf}", f"{pkg}/{kind}/{base}{suf}")] = v
    return out


class TypeTable:
    """All known types; :meth:`get` finds one by any spelling (``canon_type``)."""

    def __init__(self) -> None:
        self.types: dict[str, TypeInfo] = {}
        self.notes: list[Note] = []
        self._store: Any = None
        #: package -> the kinds (``msg``, ``srv``, ``action``) of it no definition is available of
        self.absent: dict[str, set[str]] = {}
        self._opaque: dict[str, TypeInfo] = {}

    def add_file(self, path: Path, pkg: str, shown: str, origin: str, cache: ParseCache | None,
                 files: dict[str, str] | None = None) -> None:
        """Parse one interface file; a bad one gives a located ``ROS-PARSE`` error note."""
        kind = path.suffix.lstrip(".")
        name = f"{pkg}/{path.parent.name if kind == 'idl' else kind}/{path.stem}"
        try:
            data = safefs.read_bytes(path)
            text = data.decode("utf-8", errors="replace")
        except OSError as exc:
            self.notes.append(Note(Src(shown), f"cannot read: {exc}", "ROS-PARSE", "warning" if isinstance(exc, safefs.Refused) else "error"))
            return
        sha = ParseCache.digest(data)
        if files is not None:
            files[shown] = sha

        def parse() -> Any:
            try:
                return _parse_one(kind, text, name)
            except Exception as exc:  # rosbags' parser raises several error classes
                line = 1
                m = re.search(r"line (\d+)", str(exc))
                if m:
                    line = int(m.group(1))
                msg = " ".join(str(exc).split())[:300]
                return ("error", line, f"bad {kind} definition {name}: {msg}")

        parsed = cache.get(f"iface2-{kind}-{name}", sha, parse) if cache else parse()
        if isinstance(parsed, tuple):
            self.notes.append(Note(Src(shown, parsed[1]), parsed[2], "ROS-PARSE", "error"))
            return
        lines = _field_lines(text) if kind != "idl" else {}
        for tname, (consts, fields) in parsed.items():
            self.types[tname] = TypeInfo(list(consts), list(fields), origin, shown,
                                         lines if kind == "msg" else {})

    def add_package_dir(self, root: Path, pkg: str, show: Any, origin: str, cache: ParseCache | None,
                        files: dict[str, str] | None = None) -> None:
        """Read the interface files of the package at ``root``: those in ``msg/``,
        ``srv/``, ``action/`` and every path ``rosidl_generate_interfaces`` names
        in its ``CMakeLists.txt`` (``srvs/Pause.srv``: rosidl takes any path
        relative to the package)."""
        seen: set[Path] = set()
        for sub in ("msg", "srv", "action"):
            d = root / sub
            if d.is_dir():
                for f in sorted(d.iterdir()):
                    if f.suffix in (".msg", ".srv", ".action", ".idl") and f.is_file():
                        seen.add(f.resolve())
                        self.add_file(f, pkg, show(f), origin, cache, files)
        for f in generated_interfaces(root, pkg) if origin == "workspace" else []:
            if f.resolve() not in seen:
                seen.add(f.resolve())
                self.add_file(f, pkg, show(f), origin, cache, files)

    def add_debian_standard(self, cache: ParseCache | None, share: Path = DEBIAN_SHARE,
                            services_only: bool = False) -> list[str]:
        """Register the interface packages Debian installed (``/usr/share/<pkg>/msg``,
        ``srv`` and ``action`` for a ``<pkg>`` with a ``package.xml`` or named ``*_msgs``
        or ``*_srvs``, e.g. ``std_srvs``, which has no message); returns their names.
        ``services_only``: only packages that define no message (``std_srvs``), whose
        services read the same in ROS 1 and ROS 2 (any message they use comes from
        the ROS 2 store), for a scan of ROS 2 packages only (docs/ros.md)."""
        found: list[str] = []
        if not share.is_dir():
            return found
        roots = {p.parent for sub in ("msg", "srv", "action") for p in share.glob(f"*/{sub}")}
        for root in sorted(roots):
            if not ((root / "package.xml").is_file() or root.name.endswith(("_msgs", "_srvs"))):
                continue
            if services_only and (root / "msg").is_dir():
                continue
            if root.name not in {p.split("/")[0] for p in self.types}:
                self.add_package_dir(root, root.name, lambda f: f"{root.name}/{f.parent.name}/{f.name}",
                                     "debian", cache)
                found.append(root.name)
        self.notes = [n for n in self.notes if n.severity != "error" or not n.src.file.split("/")[0] in found]
        return found

    def add_ament_index(self, cache: ParseCache | None, prefixes: Iterable[Path]) -> list[str]:
        """Register the interface packages an installed ROS 2 lists in the ament
        resource index of each prefix (``AMENT_PREFIX_PATH``'s entries:
        ``share/ament_index/resource_index/rosidl_interfaces/<pkg>`` names the
        package's interface files, found under ``share/<pkg>/``; ament_index's
        layout).  A package the scan already has (a workspace package, an earlier
        prefix) is not read again; of a package rosbags' ROS 2 store has messages
        of, only its services and actions are read, so that a scan's messages do
        not change with the installed distribution.  Returns the packages read."""
        found: list[str] = []
        have = {p.split("/")[0] for p in self.types}
        for prefix in prefixes:
            index = Path(prefix) / "share" / "ament_index" / "resource_index" / "rosidl_interfaces"
            if not index.is_dir():
                continue
            for entry in sorted(index.iterdir()):
                pkg = entry.name
                if pkg in have or not entry.is_file():
                    continue
                have.add(pkg)
                in_store = any(k.startswith(pkg + "/") for k in self._store_names())
                try:
                    listed = re.split(r"[;\n]", safefs.read_text(entry))  # one file a line (older: ';')
                except OSError:
                    continue
                share = Path(prefix) / "share" / pkg
                for rel in sorted({x.strip() for x in listed if x.strip().endswith((".msg", ".srv", ".action"))}):
                    if in_store and rel.endswith(".msg"):
                        continue
                    f = share / rel
                    if f.is_file():
                        self.add_file(f, pkg, f"{pkg}/{rel}", "ament", cache)
                found.append(pkg)
        return found

    def _store_names(self) -> Iterable[str]:
        """The type names of rosbags' ROS 2 store (loaded once)."""
        if self._store is None:
            from rclverify.core.extras import require  # deferred: optional or conditional (inside a block)
            typesys = require("rosbags.typesys", "reading the standard ROS message types")  # MissingExtra: the ros extra
            self._store = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
        return self._store.fielddefs.keys()  # type: ignore[no-any-return]

    def _fallback(self, name: str) -> TypeInfo | None:
        self._store_names()
        fd = self._store.fielddefs.get(name)
        if fd is None:
            return None
        info = TypeInfo(list(fd[0]), list(fd[1]), "rosbags")
        self.types[name] = info
        return info

    def get(self, name: str | None) -> TypeInfo | None:
        """The type ``name`` (canonical ``pkg/msg/Type``), from the workspace,
        Debian, then rosbags' store; for a type of an absent package
        (:meth:`mark_absent`) a :class:`TypeInfo` of origin :data:`ABSENT`
        without fields (known by name, its fields unknown); ``None`` when unknown."""
        if not name:
            return None
        return self.types.get(name) or self._fallback(name) or self._absent_type(name)

    def defines(self, pkg: str, kind: str) -> bool:
        """Whether any definition of package ``pkg``'s ``kind`` (``msg``, ``srv``,
        ``action``) is available: a package read from the workspace, Debian or an
        ament index has all its kinds; rosbags' store has messages only.  Raises
        ``MissingExtra`` without rosbags (the ``ros`` extra), as :meth:`get` does."""
        if any(k.startswith(pkg + "/") and v.origin != "rosbags" for k, v in self.types.items()):
            return True
        return kind == "msg" and any(k.startswith(f"{pkg}/msg/") for k in self._store_names())

    def mark_absent(self, pkg: str, kind: str) -> None:
        """Record that no definition of ``pkg``'s ``kind`` is available: its types are
        then known by name only (:meth:`get`)."""
        self.absent.setdefault(pkg, set()).add(kind)

    def _absent_type(self, name: str) -> TypeInfo | None:
        parts = name.split("/")
        if len(parts) != 3 or parts[1] not in self.absent.get(parts[0], ()):
            return None
        return self._opaque.setdefault(name, TypeInfo([], [], ABSENT))

    def closure(self, names: Iterable[str]) -> dict[str, TypeInfo]:
        """The types ``names`` and every type their fields use, transitively (known ones only)."""
        out: dict[str, TypeInfo] = {}
        todo = [n for n in names if n]
        while todo:
            n = todo.pop()
            if n in out:
                continue
            info = self.get(n)
            if info is None or info.origin == ABSENT:
                continue
            out[n] = info
            for _f, desc in info.fields:
                t, _arr = elem_type(desc)
                if t not in BASE_TYPES and "/" in t:
                    todo.append(t)
        return out

    def unknown_refs(self) -> list[tuple[str, str, str]]:
        """``(type, field, missing type)`` for workspace fields naming an unknown type."""
        out = []
        for tname, info in sorted(self.types.items()):
            if info.origin != "workspace":
                continue
            for fname, desc in info.fields:
                t, _ = elem_type(desc)
                if t not in BASE_TYPES and "/" in t and self.get(t) is None:
                    out.append((tname, fname, t))
        return out


def field_path(table: TypeTable, msg_type: str, path: str) -> tuple[str | None, str | None, bool]:
    """Follow ``path`` (``a.b[2].c``, ``a.b[-1].c``, ``a.b[].c``, ``a.b``) through ``msg_type``.

    Returns ``(ros_type, error, is_array)``: the field's ROS type (``float32``,
    ``pkg/msg/T``) and whether the final field is an array, or an error text
    naming the first segment that does not exist (with the fields there are).
    """
    cur = msg_type
    is_array = False
    for seg in path.split("."):
        m = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[-?\d*\])*)", seg)
        if not m:
            return None, f"'{seg}' is not a field name", False
        fname, index = m.group(1), m.group(2)
        info = table.get(cur)
        if info is None:
            return None, f"{cur} is not a message type with fields", False
        if info.origin == ABSENT:
            return None, (f"the fields of {cur} are unknown: its interface package {cur.split('/')[0]} is in "
                          f"neither the scanned tree nor an installed ROS"), False
        desc = dict(info.fields).get(fname)
        if desc is None:
            have = ", ".join(n for n, _ in info.fields) or "no fields"
            return None, f"{cur} has no field '{fname}' (it has: {have})", False
        t, arr = elem_type(desc)
        if index and not arr:
            return None, f"{cur}.{fname} is not an array", False
        is_array = arr and not index
        cur = t
    return cur, None, is_array
