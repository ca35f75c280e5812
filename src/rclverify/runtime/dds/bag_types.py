"""The message definitions a bag gives for the call topics it records
(services' and actions' ``*_Event`` types, an action's feedback message).

rosbags' ``.msg`` reader names every type ``<pkg>/msg/<T>`` (it reads
``std_srvs/srv/SetBool_Event`` as ``std_srvs/srv/msg/SetBool_Event``), so a
``ros2msg`` definition of a service's event type would not name the type the
topic carries.  These definitions are therefore written in rosbag2's
``ros2idl`` encoding (rosbag2 ``docs/message_definition_encoding.md``: each
type's IDL after a line of 80 ``=`` and ``IDL: <pkg>/<ns>/<T>``; the text from
``templates/definition.idl.j2``), which keeps ``srv`` and ``action`` in the
names, for the type and every type it holds, from the definitions the live
monitor decodes with (:class:`~.types.TypeBook`).  IDL types are rosidl's
(``.msg`` ``char`` is ``uint8``, ``byte`` is ``octet``, ``float64`` is
``double``; a fixed array is a ``typedef``); the type hash (REP-2011) is
rosbags' of the definition read back, which equals what rosidl wrote into
the Kilted wheels (``std_srvs/srv/SetBool_Event``:
``RIHS01_3c4c2001...``), ``service_msgs/msg/ServiceEventInfo``'s
``client_gid`` being ``uint8[16]``.

:func:`declared_store` is the type store of a type a publisher declared
(:class:`~.types.Declaration`): a contract topic's samples heard in the
publisher's own definition are recorded under that definition (rosbags
writes it as ``ros2msg`` text with the hash of it), never under the
workspace's, which would not read them back.
"""
from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING, Any

from rclverify.runtime.dds.types import DdsTypeError, Declaration, TypeBook
from rclverify.runtime.shapes import IdlMember, IdlStruct, IdlTypedef

if TYPE_CHECKING:
    from rosbags.interfaces.typing import Typesdict

#: rosidl's IDL name of each ``.msg`` primitive type
_IDL = {"bool": "boolean", "byte": "octet", "octet": "octet", "char": "uint8", "float32": "float",
        "float64": "double", "int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16",
        "int32": "int32", "uint32": "uint32", "int64": "int64", "uint64": "uint64"}


@cache
def _template() -> Any:
    import jinja2  # deferred: start-up (loads jinja2 only when a bag is recorded)
    env = jinja2.Environment(loader=jinja2.PackageLoader("rclverify.runtime.dds", "templates"),
                             undefined=jinja2.StrictUndefined, autoescape=False, keep_trailing_newline=True)
    return env.get_template("definition.idl.j2")


def _idl_type(desc: Any, owner: str, typedefs: list[IdlTypedef]) -> str:
    """The IDL type of a field description (rosbags' form), its arrays' typedefs added to ``typedefs``."""
    kind, detail = int(desc[0]), desc[1]
    if kind == 1:
        base, bound = detail
        if base == "string":
            return f"string<{int(bound)}>" if bound else "string"
        if base not in _IDL:
            raise DdsTypeError(f"{owner}: a field of type {base} cannot be described for a bag")
        return str(_IDL[base])
    if kind == 2:
        if str(detail).endswith("/wstring"):
            raise DdsTypeError(f"{owner}: rosbags has no wide string: a wstring cannot be stored")
        return str(detail).replace("/", "::")
    elem = _idl_type(detail[0], owner, typedefs)
    n = int(detail[1])
    if kind == 3:
        name = elem.replace("::", "__").replace("<", "_").replace(">", "_") + f"__{n}"
        if not any(t["name"] == name for t in typedefs):
            typedefs.append({"elem": elem, "name": name, "n": n})
        return name
    return f"sequence<{elem}, {n}>" if n else f"sequence<{elem}>"


def _nested(desc: Any) -> list[str]:
    kind, detail = int(desc[0]), desc[1]
    if kind == 2:
        return [] if str(detail).endswith("/wstring") else [str(detail)]
    if kind in (3, 4):
        return _nested(detail[0])
    return []


def definition(types: TypeBook, name: str) -> tuple[str, str]:
    """``(message definition, type hash)`` of type ``name`` (``pkg/ns/T``, as
    the book's table names it) for a bag's connection: ``ros2idl`` text of
    ``name`` and every type it holds (module docstring).  Raises
    :class:`~.types.DdsTypeError` for a type the book does not define or a
    field a bag cannot describe (a ``wstring``)."""
    from rosbags.typesys import Stores, get_typestore, get_types_from_idl  # deferred: start-up (only when recording)
    structs: list[IdlStruct] = []
    seen: set[str] = set()
    todo = [name]
    while todo:
        t = todo.pop(0)
        if t in seen:
            continue
        seen.add(t)
        info = types.table.get(t)
        if info is None:
            raise DdsTypeError(f"{name}: type {t} is neither in the workspace's interface files nor a standard type")
        typedefs: list[IdlTypedef] = []
        members: list[IdlMember] = [{"type": _idl_type(desc, t, typedefs), "name": f} for f, desc in info.fields] or \
            [{"type": "uint8", "name": "structure_needs_at_least_one_member"}]
        pkg, ns, short = t.split("/")
        structs.append({"full": t, "pkg": pkg, "ns": ns, "name": short, "typedefs": typedefs, "members": members})
        todo += [n for _f, desc in info.fields for n in _nested(desc)]
    text = _template().render(structs=structs).lstrip("\n")
    store = get_typestore(Stores.EMPTY)
    parsed: Typesdict = {}
    for chunk in text.split("=" * 80 + "\n")[1:]:
        parsed.update(get_types_from_idl(chunk.split("\n", 1)[1]))
    store.register(parsed)
    return text, str(store.hash_rihs01(name))


def declared_store(decl: Declaration) -> Any:
    """A rosbags type store holding exactly the types of ``decl`` (its
    description's fields, no constants: a description carries none), from
    which rosbags' writer makes the connection's ``ros2msg`` definition and
    hash.  Raises :class:`~.types.DdsTypeError` for a type rosbags cannot
    describe (a ``wstring``)."""
    from rosbags.typesys import Stores, get_typestore  # deferred: start-up (only when recording)
    store = get_typestore(Stores.EMPTY)
    try:
        store.register({name: ([], list(fields)) for name, fields in decl.fields.items()})
        store.generate_msgdef(decl.name, ros_version=2)
    except Exception as exc:  # rosbags' own errors: a type it cannot describe
        raise DdsTypeError(f"{decl.name} as {decl.origin} declares it cannot be described for a bag: {exc}") \
            from None
    return store


__all__ = ["declared_store", "definition"]
