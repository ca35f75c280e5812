"""NoDL documents matched to the nodes of a graph by their fully qualified names (docs/nodl.md,
"Matching documents to nodes").

A document names its node by its file name (:func:`~rclverify.model.nodl.document.node_of`),
never its namespace.  Each namespace given for a document (``--namespace NODE=NS``, repeatable:
one node run in a fleet's ``/r1`` and ``/r2``) is one expected instance, the node
``NS/<node>`` (:func:`rclverify.model.names.node_fqn`), matched to the graph's node of that
namespace whose name is the document's (compared ignoring case, ``_``, ``-``, as a contract's
node is matched: ``Relay`` is ``relay``).  A document given no namespace is one instance
matched by its base name alone, and only when that is unambiguous: exactly one node of the
graph has that name, in any namespace.  Several (``/r1/relay`` and ``/r2/relay``) match none,
and the instance says which there are and that a namespace decides.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

from rclverify.model.names import namespace_problem, split_fqn


@dataclass(frozen=True)
class Instance:
    """One expected node of a document: ``node`` the document's node (its key), ``namespace`` the
    one given for it (``None``: none given), ``running`` the graph node it matched (its fully
    qualified name; ``None``: unmatched, ``why`` says why)."""

    node: str
    namespace: str | None
    running: str | None
    why: str = ""

    @property
    def label(self) -> str:
        """The instance in words: ``Relay`` alone, or ``Relay in /r1`` when a namespace was given."""
        return self.node if self.namespace is None else f"{self.node} in {self.namespace}"

    @property
    def expected(self) -> str:
        """The fully qualified name the instance runs under: the matched node's, else ``NS/<node>``
        (``/<node>`` with no namespace given: the root namespace)."""
        if self.running is not None:
            return self.running
        ns = self.namespace or "/"
        return f"{'' if ns == '/' else ns}/{self.node}"


def node_key(name: str) -> str:
    """A node's base name as documents are matched to it: the last token of a fully qualified
    name, lower case, without ``_``, ``-``, ``@`` and ``.`` (a scanned program kept apart by its
    executable, ``/talker@pkg.exe``)."""
    return re.sub(r"[_\-@.]", "", split_fqn(name)[1] if name.startswith("/") else name).lower()


def parse_namespaces(items: Sequence[str], documents: Iterable[str]) -> dict[str, list[str]]:
    """``--namespace NODE=NS`` items as ``{document's node: [namespaces]}`` (in the order given, a
    namespace given twice kept once; a trailing ``/`` dropped).  Raises :class:`ValueError`, one
    line naming the item, for an item without ``=``, an invalid namespace (rcl's rules,
    :func:`rclverify.model.names.namespace_problem`) or a node no document is named after."""
    known = set(documents)
    out: dict[str, list[str]] = {}
    for item in items:
        node, eq, ns = item.partition("=")
        if not eq or not node:
            raise ValueError(f"--namespace {item!r}: write NODE=NAMESPACE")
        ns = ns.rstrip("/") or "/"
        why = namespace_problem(ns)
        if why is not None:
            raise ValueError(f"--namespace {item!r}: {why}")
        if node not in known:
            raise ValueError(f"--namespace {item!r}: no document is named after node {node!r} "
                             f"(documents: {', '.join(sorted(known)) or 'none'})")
        if ns not in out.setdefault(node, []):
            out[node].append(ns)
    return out


def match_instances(documents: Iterable[str], graph: Iterable[str],
                    namespaces: Mapping[str, Sequence[str]] | None = None) -> list[Instance]:
    """Each document of ``documents`` (their nodes) in each namespace ``namespaces`` gives it,
    matched among ``graph`` (fully qualified node names): module docstring.  Sorted by node, then
    namespace; raises nothing."""
    given = namespaces or {}
    by_key: dict[str, list[str]] = {}
    for g in sorted(graph):
        by_key.setdefault(node_key(g), []).append(g)
    out: list[Instance] = []
    for node in sorted(documents):
        cands = by_key.get(node_key(node), [])
        if node not in given:
            if len(cands) == 1:
                out.append(Instance(node, None, cands[0]))
            elif cands:
                out.append(Instance(node, None, None, f"its name is that of {len(cands)} nodes ({', '.join(cands)}): "
                                                      f"the base name alone is ambiguous; give each instance's "
                                                      f"namespace (--namespace {node}=NS)"))
            else:
                out.append(Instance(node, None, None, "no node has its name"))
            continue
        for ns in given[node]:
            here = [c for c in cands if split_fqn(c)[0] == ns]
            if len(here) == 1:
                out.append(Instance(node, ns, here[0]))
            else:
                others = f" (it runs as {', '.join(cands)})" if cands else ""
                out.append(Instance(node, ns, None, f"no node of namespace {ns} has its name{others}" if not here else
                                    f"{len(here)} nodes of namespace {ns} have its name ({', '.join(here)})"))
    return out


__all__ = ["Instance", "match_instances", "node_key", "parse_namespaces"]
