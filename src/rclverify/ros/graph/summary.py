"""The scan's warnings as a person reads them (docs/ros.md, "Warnings a
person reads"): grouped by cause, what dropped nodes first, then what
dropped endpoints, then what left a type or an attribute unread; each
cause on one line with its count, its first places and its packages.

A scan of a large stack gives hundreds of located warnings, most of them
the same few causes at many places (a plugin's endpoints that no parameter
file loads, a topic name a parameter gives); listed one a line, the one that
matters (a node the launch file starts and the scan dropped) is lost among
them.  Errors are never grouped: each is its own line, always shown.  The
causes are told apart by each note's code and message (the wording the
readers give them: :mod:`rclverify.ros.extract.emit`, ``launch``,
``launch_ros2``, :mod:`rclverify.ros.extract.link`, :mod:`.assemble`).
"""
from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

#: lines of the first screen: a scan with more notes than this is summarised
SCREEN = 20
#: places named per cause
PLACES = 3
#: packages named per cause
PACKAGES = 4


class _NoteLike(Protocol):
    @property
    def src(self) -> object: ...

    @property
    def message(self) -> str: ...

    @property
    def code(self) -> str: ...

    @property
    def severity(self) -> str: ...


@dataclass(frozen=True)
class Cause:
    """One cause of warnings: ``key`` (stable, for JSON and tests), ``label``
    (what the line says), ``test(code, message)`` whether a note is of it."""

    key: str
    label: str
    test: Callable[[str, str], bool]
    # what a place of this cause is named by (``OpaqueFunction launch_setup``), shown before it; "" none
    named: Callable[[str], str] | None = None


def _has(*parts: str) -> Callable[[str, str], bool]:
    return lambda _code, msg: any(p in msg for p in parts)


_NAME = re.compile(r"\b(name|topic name) is '.*', (not a string literal|discovered at run time|from )")

#: the causes, in the order they are shown: what drops nodes first
CAUSES: tuple[Cause, ...] = (
    Cause("launch-unevaluated", "launch actions not evaluated (the nodes they start are unknown)",
          lambda code, msg: code == "ROS-LAUNCH" and (" not evaluated: " in msg or "the nodes it starts" in msg
                                                      or "nodes it starts are unknown" in msg),
          named=lambda msg: msg.split(" not evaluated: ")[0] if " not evaluated: " in msg else ""),
    Cause("nodes-dropped", "launch nodes dropped (not started in the graph)",
          lambda code, msg: code == "ROS-LAUNCH" and ("action skipped" in msg or "element skipped" in msg)
          or "its topics are unknown" in msg or "its endpoints are not in the graph" in msg),
    Cause("nodes-alternative", "launch nodes under a condition not evaluated (alternatives: the first kept)",
          _has("taken as alternatives")),
    Cause("nodes-twice", "launch nodes started twice (the last kept)", _has("is started twice")),
    Cause("nodes-at-shutdown", "launch nodes of OnShutdown handlers (launch starts none: not nodes)",
          _has("is started by OnShutdown")),
    Cause("containers", "component containers (the processes holding components: not nodes, their components are)",
          lambda code, _msg: code == "ROS-CONTAINER"),
    Cause("endpoints-name", "endpoints dropped: name not read statically",
          lambda _code, msg: bool(_NAME.search(msg)) or "name of" in msg and "comes from parameter" in msg),
    Cause("endpoints-unbuilt", "endpoints of classes nothing the program runs constructs", _has("nothing this program runs")),
    Cause("endpoints-plugin", "endpoints of plugins no parameter file loads (loaded at run time)",
          _has("the plugin is loaded at run time")),
    Cause("endpoints-other", "endpoints or node names not read statically",
          lambda code, msg: code == "ROS-UNRESOLVED" and "not resolved statically" in msg and "type of" not in msg),
    Cause("interfaces", "interface packages or fields absent",
          lambda code, msg: code in ("ROS-INTERFACE-ABSENT", "ROS-FIELD-MISSING", "ROS-FIELD-TYPE")
          or "which no scanned package or standard package defines" in msg),
    Cause("types", "types not read (endpoint kept untyped)",
          lambda code, msg: "type of" in msg or code in ("ROS-TYPE", "ROS-TYPE-UNKNOWN")),
    Cause("not-built", "programs not built (ROS 1 code no target of the ament package builds: listed apart, "
                       "not nodes)", lambda code, _msg: code == "ROS-NOT-BUILT"),
    Cause("launch-run-time", "launch values known only at run time (Command, FindExecutable, a ROS parameter ...)",
          lambda code, msg: code == "ROS-LAUNCH" and "is known only at run time" in msg),
    Cause("launch-attributes", "launch attributes not read (parameter files, conditions, remappings)",
          lambda code, _msg: code == "ROS-LAUNCH"),
    Cause("parse", "sources read in part (syntax errors recovered, files skipped)",
          lambda code, _msg: code == "ROS-PARSE"),
    Cause("endpoints-own-node", "endpoints on a library's own node (tf2_ros' TransformListener given no node)",
          lambda code, _msg: code == "ROS-TF-OWN-NODE"),
    Cause("other", "other warnings", lambda _code, _msg: True),
)


def cause_of(code: str, message: str) -> Cause:
    """The first of :data:`CAUSES` a note of ``code`` saying ``message`` is of."""
    return next(c for c in CAUSES if c.test(code, message))


@dataclass
class Group:
    """The warnings of one cause: their count, places in order, packages."""

    cause: Cause
    places: list[str] = field(default_factory=list)
    packages: dict[str, int] = field(default_factory=dict)


def group(notes: Iterable[_NoteLike], package_of: Callable[[str], str | None]) -> list[Group]:
    """The warnings of ``notes`` (errors left out) grouped by cause, in the order
    of :data:`CAUSES`, only the causes present; ``package_of(file)`` names the
    package a shown path lies in (``None``: none)."""
    groups: dict[str, Group] = {}
    for n in notes:
        if n.severity == "error":
            continue
        c = cause_of(n.code, n.message)
        g = groups.setdefault(c.key, Group(c))
        what = c.named(n.message) if c.named is not None else ""
        g.places.append(f"{what} at {n.src}" if what else str(n.src))
        pkg = package_of(str(n.src).rsplit(":", 2)[0])
        if pkg is not None:
            g.packages[pkg] = g.packages.get(pkg, 0) + 1
    return [groups[c.key] for c in CAUSES if c.key in groups]


def line(g: Group) -> str:
    """One cause's line: ``count label: first places (+k more); packages: a (n), ...``."""
    first = list(dict.fromkeys(g.places))[:PLACES]
    more = len(g.places) - len(first)
    text = f"{len(g.places):>5}  {g.cause.label}: {', '.join(first)}" + (f" (+{more} more)" if more > 0 else "")
    if g.packages:
        top = sorted(g.packages.items(), key=lambda kv: (-kv[1], kv[0]))
        shown = ", ".join(f"{p} ({k})" for p, k in top[:PACKAGES])
        text += f"; packages: {shown}" + (f" and {len(top) - PACKAGES} more" if len(top) > PACKAGES else "")
    return text


FULL = "each located in the JSON's \"unresolved\"; --verbose lists them here"


def report(notes: Sequence[_NoteLike], packages: Mapping[str, str], verbose: bool = False,
           screen: int = SCREEN, full: str = FULL) -> list[str]:
    """The lines ``ros scan`` (and ``init --from-ros``) prints about ``notes``: every
    note, one a line, when ``verbose`` or when they fit in ``screen`` lines; else
    every error, then a heading saying where the full list is (``full``), then
    one line per cause of the warnings (:func:`group`).  ``packages`` maps each
    package's shown manifest path to its name."""
    if verbose or len(notes) <= screen:
        return [str(n) for n in notes]
    roots = sorted(((m.rsplit("/", 1)[0] + "/" if "/" in m else "", name) for m, name in packages.items()),
                   key=lambda r: -len(r[0]))

    def package_of(file: str) -> str | None:
        return next((name for root, name in roots if file.startswith(root)), None)
    errors = [str(n) for n in notes if n.severity == "error"]
    groups = group(notes, package_of)
    warned = sum(len(g.places) for g in groups)
    out = errors + [f"{warned} warning(s) by cause ({full}):"]
    out += [line(g) for g in groups]
    return out
