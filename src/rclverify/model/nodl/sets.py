"""NoDL documents checked against each other as a set, with or without contracts (docs/nodl.md, "Document sets").

A set is the documents of the folders and files named (a folder's
``*.nodl.yaml``, ``*.nodl.yml`` and ``*.nodl.json``, not its sub-folders);
each document that no other document of the set includes is a node, named
by its file (:func:`~rclverify.model.nodl.document.node_of`), in the
namespace given for it (default ``/``; a document given several namespaces
is one node in each).  Names are compared after ROS 2's
name resolution (:func:`resolve`).  :func:`connections` finds, per name
two nodes share,

* ``nodl-connect-type``: a topic's, service's or action's two ends typed differently;
* ``nodl-qos``: a topic's publisher offering less than its subscription
  requests, or a service's client and server in either direction
  (:func:`rclverify.model.nodl.qos.mismatches`, DDS's request-offered rules);

and :func:`unserved` (the set check only) finds

* ``nodl-no-publisher``: a subscription no node of the set publishes;
* ``nodl-no-server``: a service or action client no node of the set serves;

unless the name is declared external (it comes from outside the set: a
driver, a bag, another machine).  The check is the one
ros-tooling/nodl#182 asks for: a CI status without starting a node.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Mapping, Sequence

from rclverify.lang import ast
from rclverify.model.nodl.contract import type_key
from rclverify.model.nodl.document import SUFFIXES, Document, Endpoint, Resolver
from rclverify.model.nodl.findings import Finding
from rclverify.model.nodl.qos import mismatches

#: Writer list, reader list and what the name is, for each kind of connection.
PAIRS = (("publishers", "subscriptions", "topic"), ("service_servers", "service_clients", "service"),
         ("action_servers", "action_clients", "action"))


@dataclass(frozen=True)
class Member:
    """One node of a set: ``node`` its name (the document's file name), ``namespace`` the one it
    runs in (absolute, ``/`` the root), ``doc`` its document with its includes merged."""

    node: str
    namespace: str
    doc: Document

    @property
    def label(self) -> str:
        """How messages name the node: its name in the root namespace, else its fully qualified name."""
        return self.node if self.namespace == "/" else resolve("~", self.node, self.namespace)

    def name(self, e: Endpoint) -> str:
        """Endpoint ``e``'s name resolved for this node (:func:`resolve`)."""
        return resolve(e.name, self.node, self.namespace)


@dataclass
class SetResult:
    """What :func:`check_set` read and found: ``members`` (the nodes), ``parts`` (documents another
    of the set includes), ``findings`` in file order."""

    members: list[Member] = field(default_factory=list)
    parts: list[Document] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)

    @property
    def errors(self) -> int:
        """How many findings are errors."""
        return sum(f.severity == "error" for f in self.findings)


def namespace_of(text: str) -> str:
    """``text`` as an absolute namespace without a trailing ``/`` (the root is ``/``); raises
    :class:`ValueError` for a character a ROS 2 name does not allow or a ``~``."""
    body = text.strip("/")
    if any(not (c.isalnum() or c in "_/") for c in body) or "//" in body:
        raise ValueError(f"namespace {text!r}: a ROS 2 namespace holds letters, digits, '_' and '/'")
    return "/" + body


def resolve(name: str, node: str, namespace: str = "/") -> str:
    """``name`` fully qualified as ROS 2 resolves it for node ``node`` in ``namespace``
    (rcl's ``rcl_expand_topic_name``, the ROS 2 design article "Topic and Service name mapping"):
    ``{node}`` and ``{ns}`` (``{namespace}``) substituted; ``~`` is the node's fully qualified
    name, ``~/x`` below it; ``/x`` stays; a relative ``x`` is ``<namespace>/x``."""
    ns = namespace.rstrip("/")
    name = name.replace("{node}", node).replace("{ns}", ns or "/").replace("{namespace}", ns or "/")
    while "//" in name:  # "{ns}/x" in the root namespace
        name = name.replace("//", "/")
    if name == "~":
        return f"{ns}/{node}"
    if name.startswith("~/"):
        return f"{ns}/{node}/{name[2:]}"
    if name.startswith("/"):
        return name.rstrip("/") or "/"
    return f"{ns}/{name}".rstrip("/")


def connections(members: Sequence[Member]) -> list[Finding]:
    """The type and QoS findings between the ends the ``members`` give one resolved name
    (module docstring): each writer (publisher, server) with each reader (subscription, client)."""
    ends: dict[str, list[tuple[str, Endpoint]]] = {}
    for m in members:
        for e in m.doc.endpoints:
            ends.setdefault(m.name(e), []).append((m.label, e))
    out: list[Finding] = []
    for fqn, group in sorted(ends.items()):
        for give, take, what in PAIRS:
            for writer in (x for x in group if x[1].kind == give):
                for reader in (x for x in group if x[1].kind == take):
                    out += _pair(fqn, what, writer, reader)
    return out


def _pair(fqn: str, what: str, writer: tuple[str, Endpoint], reader: tuple[str, Endpoint]) -> list[Finding]:
    """The findings of one writer (publisher, server) and one reader (subscription, client) of ``fqn``."""
    (w_node, w), (r_node, r) = writer, reader
    if type_key(w.type) != type_key(r.type):
        return [Finding("nodl-connect-type", f"{what} {fqn}: {w_node}'s NoDL document gives it type {w.type}, "
                                             f"{r_node}'s {r.type}", (r.type_loc, w.type_loc))]
    if what == "action":
        return []
    sides = [("", w.qos, r.qos)] if what == "topic" else [(" (requests)", r.qos, w.qos), (" (responses)", w.qos, r.qos)]
    out = []
    for part, offered, requested in sides:
        if what == "service" and offered is None and requested is None:
            continue
        for m in mismatches(offered, requested):
            role = ("publisher", "subscriber") if what == "topic" else \
                ("client", "server") if part == " (requests)" else ("server", "client")
            who = (w_node, r_node) if what == "topic" or part == " (responses)" else (r_node, w_node)
            out.append(Finding("nodl-qos", f"{what} {fqn}{part}: the {role[0]} {who[0]} and the {role[1]} {who[1]} "
                                           f"never connect: {m.why} ({m.policy}: offered {m.offered}, requested "
                                           f"{m.requested})", (_at(r, m.policy), _at(w, m.policy))))
    return out


def _at(e: Endpoint, policy: str) -> ast.Loc:
    """Where endpoint ``e`` writes QoS ``policy``: the field, else its ``qos``, else its name."""
    return e.qos.where(policy) if e.qos is not None else e.loc


def unserved(members: Sequence[Member], external: Iterable[str] = ()) -> list[Finding]:
    """``nodl-no-publisher`` per subscription and ``nodl-no-server`` per service or action client
    whose resolved name no member writes (of the same list pair, whatever its type or QoS:
    :func:`connections` judges those), at the reader's entry; a name of ``external`` (resolved in
    the root namespace) is served from outside the set and not reported."""
    outside = {resolve(n, "", "/") for n in external}
    writers = {(give, m.name(e)) for m in members for give, _, _ in PAIRS for e in m.doc.of(give)}
    out: list[Finding] = []
    for m in members:
        for give, take, what in PAIRS:
            for e in m.doc.of(take):
                fqn = m.name(e)
                if fqn in outside or (give, fqn) in writers:
                    continue
                code, word = ("nodl-no-publisher", "publishes") if what == "topic" else ("nodl-no-server", "serves")
                out.append(Finding(code, f"{what} {fqn}: {m.label} {'subscribes to' if what == 'topic' else 'calls'} "
                                         f"it and no document of the set {word} it (declare it external if it comes "
                                         "from outside the set)", (e.loc,)))
    return out


def set_files(paths: Sequence[Path]) -> list[Path]:
    """The documents ``paths`` name: a folder's ``*.nodl.yaml``, ``*.nodl.yml`` and ``*.nodl.json``
    (not its sub-folders'), sorted by name; a file as given.  Raises :class:`ValueError` for a
    path that does not exist or a folder without a document."""
    out: list[Path] = []
    for p in paths:
        if p.is_dir():
            found = sorted(f for f in p.iterdir() if f.is_file() and f.name.endswith(SUFFIXES))
            if not found:
                raise ValueError(f"{p}: no NoDL document (*.nodl.yaml, *.nodl.yml, *.nodl.json) in this folder")
            out += found
        elif p.exists():
            out.append(p)
        else:
            raise ValueError(f"{p}: no such file or folder")
    return list(dict.fromkeys(out))


def members_of(docs: Sequence[Document], namespaces: Mapping[str, Sequence[str]] | None = None
               ) -> tuple[list[Member], list[Document]]:
    """``(members, parts)`` of ``docs``: a document another one includes is a part, every other a
    member per namespace ``namespaces`` gives its node (node -> namespaces; none given: ``/``), so
    one document run in several namespaces is several nodes."""
    included = {f for d in docs for f in d.files[1:]}
    ns = namespaces or {}
    members = [Member(d.node, n, d) for d in docs if d.file not in included for n in (ns.get(d.node) or ("/",))]
    return members, [d for d in docs if d.file in included]


def check_set(docs: Sequence[Document], namespaces: Mapping[str, Sequence[str]] | None = None,
              external: Iterable[str] = ()) -> SetResult:
    """Check the documents ``docs`` (read: :func:`rclverify.model.nodl.check.read_all`) against
    each other (module docstring); ``namespaces`` node -> the namespaces it runs in (:func:`members_of`),
    ``external`` names served from
    outside the set."""
    members, parts = members_of(docs, namespaces)
    res = SetResult(members, parts)
    res.findings = connections(members) + unserved(members, external)
    res.findings.sort(key=lambda f: (f.locs[0].file, f.locs[0].line, f.locs[0].col, f.code))
    return res


def set_resolver(paths: Sequence[Path], prefixes: Sequence[Path], display: Callable[[Path], str]) -> Resolver:
    """A :class:`Resolver` for a set named on the command line (``prefixes`` resolve ``nodl://``,
    ``display`` names files): every document read, an include too, must lie in one of the folders
    named or the folder of a file named."""
    return Resolver(prefixes, display, [p if p.is_dir() else p.parent for p in paths])


__all__ = ["Member", "PAIRS", "SetResult", "check_set", "connections", "members_of", "namespace_of", "resolve",
           "set_files", "set_resolver", "unserved"]
