"""Interface packages the scan has no definition of (docs/ros.md, "Absent interface packages").

A type the code or a scanned ``.msg``/``.srv``/``.action`` file names is
defined by a scanned package, an installed ROS (Debian's ``/usr/share``, a
sourced ROS 2's ament index) or rosbags' store of ROS 2 messages.  When its
package is none of these for the type's kind (``msg``, ``srv``, ``action``:
rosbags' store holds messages only), the package is *absent*: one located
``ROS-INTERFACE-ABSENT`` warning per package, at its first use, names it and
everything it leaves untyped (topics, services, actions, fields), and the
type table knows its types by name only (:meth:`TypeTable.mark_absent`), so
every endpoint keeps its type name and every later reader (the skeletons,
the grounding) treats the package's topic, service, action and field types
alike.  A type of a package that *is* there but lacks it stays unknown: a
``ROS-TYPE`` note for a field, a grounding error for a contract's type.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.ros.extract.interfaces import TypeTable
from rclverify.ros.extract.model import SERVICE_ROLES, Graph, Note, Src, short_type

#: the code of the one note per absent package
CODE = "ROS-INTERFACE-ABSENT"
#: how many uses a note lists before it counts the rest
MAX_LISTED = 8
_ROLE_WORDS = {"pub": "topic", "sub": "topic", "service_servers": "service", "service_clients": "service",
               "action_servers": "action", "action_clients": "action"}
_PART = {"service": "_Request", "action": "_Goal", "topic": ""}
#: the kinds of interface, as a type name's middle part says them, and how a note names them
_KINDS = {"msg": "messages", "srv": "services", "action": "actions"}


@dataclass
class _Uses:
    """One package's uses: where first, each as text, and the kinds they need."""

    first: Src
    said: list[str] = field(default_factory=list)
    kinds: set[str] = field(default_factory=set)

    def add(self, text: str, kind: str) -> None:
        if text not in self.said:
            self.said.append(text)
        self.kinds.add(kind)


#: one use of a type the table does not know: (type, kind, where, what it types, the note when its package is there)
_Use = tuple[str, str, Src, str, "Note | None"]


def _endpoint_uses(g: Graph, table: TypeTable) -> list[_Use]:
    """Each endpoint whose type the table does not know (the grounding says so of a contract's type)."""
    out: list[_Use] = []
    for n in sorted(g.nodes.values(), key=lambda n: n.name):
        for role in ("pub", "sub") + SERVICE_ROLES:
            what = _ROLE_WORDS[role]
            for e in sorted(n.edges_of(role), key=lambda e: (e.topic, e.src.file, e.src.line)):
                if e.msg_type and e.msg_type.count("/") == 2 and table.get(e.msg_type + _PART[what]) is None:
                    out.append((e.msg_type, e.msg_type.split("/")[1], e.src,
                                f"{what} {e.topic} ({short_type(e.msg_type)}) of {n.name}", None))
    return out


def _field_uses(table: TypeTable) -> list[_Use]:
    """Each field of a scanned type whose type the table does not know, with its ``ROS-TYPE`` note."""
    out: list[_Use] = []
    for tname, fname, missing in table.unknown_refs():
        info = table.types[tname]
        at = Src(info.file or tname, info.lines.get(fname, 1))
        note = Note(at, f"field '{fname}' of {tname} has type {missing}, which no scanned package or standard "
                        f"package defines", "ROS-TYPE")
        out.append((missing, missing.split("/")[1] if missing.count("/") == 2 else "msg", at,
                    f"field {fname} of {short_type(tname)} ({short_type(missing)})", note))
    return out


def absent_interfaces(g: Graph, table: TypeTable, scanned: set[str], judge: bool = True) -> list[Note]:
    """The notes of the types nothing defines, after marking the absent packages in ``table``.

    ``g``: the assembled graph; ``scanned``: the names of the scanned packages
    (never absent: a type one of them lacks is unknown); ``judge``: whether the
    installed packages were read (``scan(standard=False)`` reads none: then no
    package is said absent).  Returns one ``ROS-INTERFACE-ABSENT`` warning per
    absent package (sorted by name) and one ``ROS-TYPE`` warning per field of a
    scanned type whose type a present package lacks (every such field without
    ``judge``).  Never raises on the graph's content.
    """
    fields = _field_uses(table)  # before any package is marked (a marked one's types are known)
    by_pkg: dict[str, _Uses] = {}
    notes: list[Note] = []
    there: dict[tuple[str, str], bool] = {}  # (package, kind) -> whether defined (one look per pair)
    for tname, kind, at, text, note in _endpoint_uses(g, table) + fields:
        pkg = tname.split("/")[0]
        if (pkg, kind) not in there:
            there[(pkg, kind)] = (not judge or pkg in scanned or kind not in _KINDS  # pkg::detail::T: no interface
                                  or table.defines(pkg, kind))
        if there[(pkg, kind)]:
            if note is not None:
                notes.append(note)
            continue
        by_pkg.setdefault(pkg, _Uses(at)).add(text, kind)
    for pkg, uses in sorted(by_pkg.items()):
        for kind in sorted(uses.kinds):
            table.mark_absent(pkg, kind)
        notes.append(_note(pkg, uses))
    return notes


def _note(pkg: str, uses: _Uses) -> Note:
    """The one warning of absent package ``pkg``."""
    listed = uses.said[:MAX_LISTED]
    more = len(uses.said) - len(listed)
    kinds = "its " + " and ".join(_KINDS[k] for k in sorted(uses.kinds))
    return Note(uses.first, f"interface package {pkg} is in neither the scanned tree nor an installed ROS (none "
                            f"of {kinds} is defined): these keep their type names, untyped: {'; '.join(listed)}"
                            + (f"; and {more} more" if more else ""), CODE)
