"""ROS 2 message, service and action types as Cyclone DDS structs, made at
run time from the ``.msg``/``.srv``/``.action`` definitions the workspace
already reads (rosbags' parser, through :class:`rclverify.ros.extract.interfaces.TypeTable`;
the standard packages from Debian's or rosbags' store): no IDL file, no
build step, no ROS installation.

* Definitions: the workspace's files first, then rosbags' store of ROS 2's
  standard messages, then Debian's service and action files (ROS 1
  packages, whose ``.msg`` files are not used: ROS 1's ``Header`` is not
  ROS 2's).
* A message ``pkg/msg/T`` is a struct named ``pkg::msg::dds_::T_``, its fields
  in definition order with their IDL types (``string<=N`` a bounded string,
  ``T[N]`` an array, ``T[]``/``T[<=N]`` a sequence, ``char`` an unsigned
  byte as ROS 2 maps it); a definition without fields gets
  ``uint8 structure_needs_at_least_one_member``, as rosidl does.
* A service part on the wire is rmw_cyclonedds' request wrapper: the
  client's request-writer handle (``uint64``) and a sequence number
  (``int64``) before the part's fields (``cdds_request_header_t``,
  rmw_cyclonedds ``serdata.hpp``), in both the request and the reply, which
  is how a reply names its request.  The struct has them as its first two
  members, :data:`HEADER_FIELDS`; :func:`to_fields` leaves them out.
* An action ``pkg/action/T`` (ROS 2 design "Actions") is the services
  ``T_SendGoal`` (``goal_id`` + ``goal``; ``accepted`` + ``stamp``) and
  ``T_GetResult`` (``goal_id``; ``status`` + ``result``) and the message
  ``T_FeedbackMessage`` (``goal_id`` + ``feedback``), all in ``pkg::action``;
  status is ``action_msgs/msg/GoalStatusArray``.

A ``wstring`` (Cyclone's Python binding has no wide string) is carried as
what ROS 2's middlewares put on the wire in plain CDR: a ``uint32`` count,
then one 4-byte code unit per character (``wchar_t`` on Linux; rmw_fastrtps'
``rosidl_typesupport_fastrtps`` and rmw_cyclonedds' legacy-CDR writer
alike, measured with ``test_msgs/WStrings`` from Fast DDS 3), so the struct
holds ``sequence<uint32>`` and :func:`to_fields` gives the text back;
rosbags cannot describe a ``wstring``, so such a topic cannot be recorded
(``--record`` says so).  Every error is a :class:`DdsTypeError` naming the
type and, for the workspace's files, the file.

**The publisher's own definition.**  A sample of a publisher whose type
hash is not the book's definition's is handed on as :class:`Declared`
bytes, and every struct of a book reads those with their declaration's
struct (:meth:`TypeBook.struct`); the declaration is made from the
publisher's type description by :mod:`.type_descriptions` (docs/ros2.md,
"The publisher's own definition").  A received sample is read as fields by
:mod:`.sample_fields` (:func:`to_fields`, :func:`request_id`, re-exported here).
"""
from __future__ import annotations

import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

from rclverify.ros.live.dds import dds_type, import_cyclonedds
from rclverify.ros.live.dds_xtypes import as_fast_dds
from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.interfaces import TypeInfo
from rclverify.ros.live.dds import ros_type
from rclverify.ros.live.type_hash import UnknownType, rihs01
from rclverify.runtime.dds.sample_fields import (HEADER_FIELDS, PLACEHOLDER, WIDE, request_id, to_fields, wide_depth,
                                                 wide_units)

_BASE = {"bool": "bool", "byte": "uint8", "octet": "uint8", "char": "uint8", "int8": "int8", "uint8": "uint8",
         "int16": "int16", "uint16": "uint16", "int32": "int32", "uint32": "uint32", "int64": "int64",
         "uint64": "uint64", "float32": "float32", "float64": "float64"}


class DdsTypeError(Exception):
    """A type that cannot be made (unknown, or with a field Cyclone cannot carry); ``str`` says which."""


@dataclass(frozen=True)
class Declaration:
    """A message type as a publisher declared it (module docstring): ``name``
    (``pkg/msg/T``), ``type_hash`` (``RIHS01_...``, checked against
    ``fields``), ``origin`` (where the description came from, as said to
    the user), ``struct`` (the struct its samples are read with) and
    ``fields`` (every type of the description, ``pkg/ns/T`` -> its fields in
    rosbags' form, ``(name, (kind, detail))``: what a bag of its samples
    records, :func:`~.bag_types.declared_store`)."""

    name: str
    type_hash: str
    origin: str
    struct: type
    fields: Mapping[str, list[tuple[str, Any]]]


class Declared(bytes):
    """One sample's serialized bytes (CDR with its encapsulation header)
    written in ``declaration``'s definition rather than the book's; a book's
    struct reads them with ``declaration.struct`` (module docstring)."""

    declaration: Declaration

    @classmethod
    def of(cls, raw: bytes, declaration: Declaration) -> Declared:
        """``raw`` tagged with ``declaration``."""
        out = cls(raw)
        out.declaration = declaration
        return out


@dataclass(frozen=True)
class ActionTypes:
    """The structs of one action: the two services (request, reply: with the
    request header) and the feedback message; ``status`` the status array."""

    send_goal: tuple[type, type]
    get_result: tuple[type, type]
    feedback: type
    status: type


def _package_dirs(dirs: Sequence[Path]) -> list[Path]:
    """Each ``<dir>/<pkg>`` holding ``msg``, ``srv`` or ``action`` (a directory named
    like a package is itself accepted)."""
    out: list[Path] = []
    for d in dirs:
        d = Path(d)
        if any((d / s).is_dir() for s in ("msg", "srv", "action")):
            out.append(d)
        elif d.is_dir():
            out += [p for p in sorted(d.iterdir()) if any((p / s).is_dir() for s in ("msg", "srv", "action"))]
    return out


class TypeBook:
    """Structs made on demand from the definitions under ``dirs`` (each
    holding ``<pkg>/msg``, ``srv``, ``action``) and the standard packages.

    Raises :class:`DdsTypeError` from the constructor for a definition that
    does not parse (with its file and line), from :meth:`message`,
    :meth:`service` and :meth:`action` for an unknown or unsupported type.
    """

    def __init__(self, dirs: Sequence[Path] = ()) -> None:
        import_cyclonedds()
        self.table = TypeTable()
        for pkg_dir in _package_dirs(dirs):
            self.table.add_package_dir(pkg_dir, pkg_dir.name, lambda f: str(f), "workspace", None)
        self._add_debian_services()
        bad = [n for n in self.table.notes if n.severity == "error"]
        if bad:
            raise DdsTypeError(f"{bad[0].src}: error: {bad[0].message}")
        self._structs: dict[str, type] = {}
        #: per struct: field -> nested struct class (a message or a sequence/array of them), for building
        self.nested: dict[type, dict[str, type]] = {}
        self._hints: dict[type, dict[str, object]] = {}

    @classmethod
    def described(cls, types: Mapping[str, list[tuple[str, Any]]]) -> TypeBook:
        """A book of ``types`` only (type name -> fields in rosbags' form: a
        type description's, :func:`declare`), without the workspace's or the
        standard definitions; its structs are made as :meth:`struct` makes them."""
        import_cyclonedds()
        book = cls.__new__(cls)
        book.table = TypeTable()
        book.table.types.update({n: TypeInfo([], list(fs), "described") for n, fs in types.items()})
        book._structs, book.nested, book._hints = {}, {}, {}
        return book

    def add_declaration(self, decl: Declaration) -> list[str]:
        """Define, from ``decl``'s description, each of its types this book does not define (a
        contract type with no local definition, and the types it nests that none defines); the
        book's own definitions stay.  Returns the types added; a struct already made is unchanged."""
        added = [n for n in decl.fields if self.table.get(n) is None]
        for n in added:
            self.table.types[n] = TypeInfo([], list(decl.fields[n]), "declared")
        return added

    def _add_debian_services(self, share: Path = Path("/usr/share")) -> None:
        """Debian's ``/usr/share/<pkg>/srv`` and ``action`` files for packages the
        workspace does not define (``std_srvs``): ROS 1 packages, whose
        service definitions ROS 2 kept; their ``msg`` files are not read (ROS
        1's ``Header`` has a ``seq`` ROS 2 dropped: messages come from
        rosbags' ROS 2 store)."""
        have = {n.split("/")[0] for n in self.table.types}
        for sub in ("srv", "action"):
            for d in sorted(share.glob(f"*/{sub}")) if share.is_dir() else ():
                if d.parent.name in have:
                    continue
                for f in sorted(d.glob(f"*.{sub}")):
                    if f.is_file():
                        self.table.add_file(f, d.parent.name, str(f), "debian", None)
        self.table.notes = [n for n in self.table.notes
                            if n.severity != "error" or not n.src.file.startswith(str(share))]

    # -- structs ---------------------------------------------------------------------------
    def _info(self, name: str, used_by: str = "") -> Any:
        info = self.table.get(name)
        if info is None:
            pkg, _, short = name.rpartition("/")
            kind = pkg.rpartition("/")[2] or "msg"
            file = f"{pkg}/{short if kind == 'msg' else short.split('_')[0]}.{kind}"  # a service's, an action's file
            raise DdsTypeError(f"message type {name} is neither in the workspace's interface files nor a standard "
                               f"type" + (f" (used by {used_by})" if used_by else "") + f": give its definition as "
                               f"DIR/{file} with --interfaces DIR (or the mapping's msg_dirs)")
        return info

    def _field_type(self, desc: Any, owner: str, fname: str) -> tuple[Any, type | None]:
        from cyclonedds.idl import types as T  # deferred: start-up (loads cyclonedds and more only when called)
        kind, detail = int(desc[0]), desc[1]
        if kind == 1:
            base, bound = detail
            if base == "string":
                return (T.bounded_str[int(bound)] if bound else str), None  # type: ignore[misc]
            if base in _BASE:
                return (bool if base == "bool" else getattr(T, _BASE[base])), None
            raise DdsTypeError(f"{owner}: field {fname} has type {base}, which Cyclone's Python binding cannot carry")
        if kind == 2:
            if wide_depth(desc) == 0:
                return T.sequence[T.uint32], None  # type: ignore[misc]  # a wstring's wire form (module docstring)
            cls = self.struct(str(detail), owner)
            return cls, cls
        elem, inner = self._field_type(detail[0], owner, fname)
        n = int(detail[1])
        if kind == 3:
            return T.array[elem, n], inner  # type: ignore[misc]
        return (T.sequence[elem, n] if n else T.sequence[elem]), inner  # type: ignore[misc]

    def struct(self, name: str, used_by: str = "", header: bool = False) -> type:
        """The struct of type ``name`` (``pkg/msg/T``, ``pkg/srv/T_Request``,
        ``pkg/action/T_Goal`` ...), with the request header first when ``header``."""
        key = name + ("+header" if header else "")
        hit = self._structs.get(key)
        if hit is not None:
            return hit
        from cyclonedds.idl import make_idl_struct  # deferred: start-up (loads cyclonedds and more only when called)
        from cyclonedds.idl import types as T  # deferred: start-up (loads cyclonedds and more only when called)
        info = self._info(name, used_by)
        fields: dict[str, object] = {}
        nested: dict[str, type] = {}
        if header:
            fields[HEADER_FIELDS[0]] = T.uint64
            fields[HEADER_FIELDS[1]] = T.int64
        for fname, desc in info.fields:
            fields[fname], inner = self._field_type(desc, name, fname)
            if inner is not None:
                nested[fname] = inner
        if not info.fields:
            fields[PLACEHOLDER] = T.uint8
        cls = as_fast_dds(make_idl_struct(name.rsplit("/", 1)[-1] + "_", dds_type(name), fields))
        setattr(cls, "deserialize", classmethod(_read))  # Declared bytes: read in their own definition
        wide = {f: d for f, d in ((f, wide_depth(desc)) for f, desc in info.fields) if d is not None}
        if wide:
            setattr(cls, WIDE, wide)
        self._structs[key] = cls
        self.nested[cls] = nested
        return cls

    def message(self, msg_type: str) -> type:
        """The struct of message ``pkg/T`` or ``pkg/msg/T``."""
        pkg, _, rest = msg_type.replace("/msg/", "/").partition("/")
        return self.struct(f"{pkg}/msg/{rest}")

    def service(self, srv_type: str) -> tuple[type, type]:
        """``(request, reply)`` structs of service ``pkg/T`` or ``pkg/srv/T``, with the request header."""
        pkg, _, rest = srv_type.replace("/srv/", "/").partition("/")
        return (self.struct(f"{pkg}/srv/{rest}_Request", header=True),
                self.struct(f"{pkg}/srv/{rest}_Response", header=True))

    def _synth(self, name: str, fields: list[tuple[str, Any]]) -> None:
        if self.table.get(name) is None:
            self.table.types[name] = TypeInfo([], fields, "rclverify")

    def action(self, action_type: str) -> ActionTypes:
        """The structs of action ``pkg/T`` or ``pkg/action/T`` (module docstring)."""
        pkg, _, rest = action_type.replace("/action/", "/").partition("/")
        base = f"{pkg}/action/{rest}"
        for part in ("Goal", "Result", "Feedback"):
            self._info(f"{base}_{part}", action_type)
        uuid = (2, "unique_identifier_msgs/msg/UUID")
        self._synth(f"{base}_SendGoal_Request", [("goal_id", uuid), ("goal", (2, f"{base}_Goal"))])
        self._synth(f"{base}_SendGoal_Response", [("accepted", (1, ("bool", 0))),
                                                  ("stamp", (2, "builtin_interfaces/msg/Time"))])
        self._synth(f"{base}_GetResult_Request", [("goal_id", uuid)])
        self._synth(f"{base}_GetResult_Response", [("status", (1, ("int8", 0))), ("result", (2, f"{base}_Result"))])
        self._synth(f"{base}_FeedbackMessage", [("goal_id", uuid), ("feedback", (2, f"{base}_Feedback"))])
        return ActionTypes(
            send_goal=(self.struct(f"{base}_SendGoal_Request", header=True),
                       self.struct(f"{base}_SendGoal_Response", header=True)),
            get_result=(self.struct(f"{base}_GetResult_Request", header=True),
                        self.struct(f"{base}_GetResult_Response", header=True)),
            feedback=self.struct(f"{base}_FeedbackMessage"),
            status=self.struct("action_msgs/msg/GoalStatusArray"))

    def type_hash(self, cls: type) -> str | None:
        """The ROS 2 type hash (``RIHS01_...``, REP-2011, :mod:`rclverify.ros.live.type_hash`)
        of message struct ``cls`` from the definitions this book reads: what a
        ROS 2 publisher of the same definition announces.  ``None`` for a
        service part or request-header struct."""
        name = ros_type(getattr(cls, "__idl_typename__", ""))
        if name is None or "/msg/" not in name:
            return None

        def fields_of(t: str) -> Any:
            info = self.table.get(t)
            return None if info is None else info.fields
        try:
            return rihs01(name, fields_of)
        except (UnknownType, KeyError, ValueError, TypeError):
            return None

    # -- values ------------------------------------------------------------------------------
    def build(self, cls: type, data: Mapping[str, Any]) -> Any:
        """An instance of struct ``cls`` from a dict (nested dicts and lists of
        dicts for nested messages, text for a wstring; a field not given has its zero value)."""
        nested = self.nested.get(cls, {})
        wide = getattr(cls, WIDE, {})
        hints = self._hints.get(cls)
        if hints is None:
            hints = self._hints[cls] = typing.get_type_hints(cls, include_extras=True)
        kw: dict[str, Any] = {}
        for fname, ann in hints.items():
            inner = nested.get(fname)
            if fname not in data:
                kw[fname] = self._zero(ann, inner)
                continue
            v = data[fname]
            if fname in wide:
                v = wide_units(v, wide[fname])
            if inner is not None:
                v = [self.build(inner, x) for x in v] if isinstance(v, (list, tuple)) else self.build(inner, v)
            kw[fname] = v
        return cls(**kw)

    def _zero(self, ann: Any, inner: type | None) -> Any:
        """The zero value of a field of annotation ``ann`` (``inner``: its struct, if any)."""
        meta = getattr(ann, "__metadata__", ())
        tag = meta[0] if meta else None
        kind = type(tag).__name__
        if kind == "array" and tag is not None:
            return [self._zero(tag.subtype, inner) for _ in range(tag.length)]
        if kind == "sequence":
            return []
        if inner is not None:
            return self.build(inner, {})
        base = typing.get_args(ann)[0] if meta else ann
        if kind == "bounded_str" or base is str:
            return ""
        return False if base is bool else 0.0 if base is float else 0


def _read(cls: Any, data: bytes, has_header: bool = True, use_version_2: bool | None = None) -> Any:
    """``cls.deserialize``: ``data`` as an instance of ``cls``, or of its
    declaration's struct for :class:`Declared` bytes (module docstring).
    Raises what Cyclone's deserializer raises for bytes of another layout."""
    decl = getattr(data, "declaration", None)
    if decl is not None and decl.struct is not cls:
        return decl.struct.deserialize(bytes(data), has_header=has_header, use_version_2=use_version_2)
    return cls.__idl__.deserialize(data, has_header=has_header, use_version_2=use_version_2)


__all__ = ["ActionTypes", "DdsTypeError", "Declaration", "Declared", "HEADER_FIELDS", "TypeBook", "request_id",
           "to_fields"]
