"""The system model: which node outputs feed which node inputs.

Connections (shared/DESIGN.md "Semantics"; paper lines 437-461 on system
models) are found, for each input of each node, in this order:

1. the plan's explicit ``connections`` (``via = "plan"``);
2. an output of another node with the same name and the same type
   (``via = "name"``);
3. the other end of a service or action link of the same name (rule S1,
   :mod:`.services`; ``via = "service"``);
4. an output of another node bound to the same ROS topic field
   (``msg_type`` and ``field``; ``via = "topic"``).

Anything unconnected is an *environment input*.  Inputs of the empty type
``{}`` (hardware, e.g. ``SensorsType``) are always environment inputs.
An input that two or more nodes could feed by name or topic is ambiguous and
is an error asking for an explicit connection in the plan.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import Any, Iterable, Mapping, Sequence

from rclverify.model.plan.model import Connection
from rclverify.lang.errors import RclError, error
from rclverify.lang.types import Checked, EmptyT
from rclverify.model.system.services import peers as service_peers, side_conditions as service_conditions
from rclverify.model.system.units import connection_diagnostics
from rclverify.model.system.cycles import elementary_cycles, strongly_connected_components, upstream_bits
from rclverify.model.system.shapes import LinkJson, ModelJson, ModelView


@dataclass(frozen=True)
class Link:
    """``from_node.out.from_var`` feeds ``to_node.in.to_var``."""

    from_node: str
    from_var: str
    to_node: str
    to_var: str
    via: str

    def to_json(self) -> LinkJson:
        return {"from_node": self.from_node, "from_var": self.from_var, "to_node": self.to_node,
                "to_var": self.to_var, "via": self.via}


def names_of(mask: int, order: Sequence[str], limit: int | None = None) -> list[str]:
    """The names of ``order`` whose bits are set in ``mask`` (bit ``i`` is
    ``order[i]``), in that order; at most ``limit`` of them."""
    out: list[str] = []
    while mask and (limit is None or len(out) < limit):
        low = mask & -mask
        out.append(order[low.bit_length() - 1])
        mask ^= low
    return out


@dataclass(frozen=True)
class SystemModel:
    """Nodes (source order), links, environment inputs and loops.

    ``env_inputs`` are ``(node, var, type)`` triples; ``loops`` are the
    strongly connected components with a cycle, each sorted by node name.
    """

    nodes: tuple[str, ...]
    links: tuple[Link, ...]
    env_inputs: tuple[tuple[str, str, str], ...]
    loops: tuple[tuple[str, ...], ...]

    @cached_property
    def _index(self) -> dict[str, tuple[list[str], list[str], set[str]]]:
        """Per node: (producers, consumers, internal inputs), built once in
        O(links) so that the per-node queries below do not scan every link
        (with them a 1000-node system's calculus was quadratic in the links)."""
        order = {n: k for k, n in enumerate(self.nodes)}
        prod: dict[str, set[str]] = {n: set() for n in self.nodes}
        cons: dict[str, set[str]] = {n: set() for n in self.nodes}
        ins: dict[str, set[str]] = {n: set() for n in self.nodes}
        for l in self.links:
            prod.setdefault(l.to_node, set()).add(l.from_node)
            cons.setdefault(l.from_node, set()).add(l.to_node)
            ins.setdefault(l.to_node, set()).add(l.to_var)

        def ordered(names: set[str]) -> list[str]:
            return sorted((n for n in names if n in order), key=order.__getitem__)
        return {n: (ordered(prod[n]), ordered(cons.get(n, set())), ins[n]) for n in prod}

    def producers(self, node: str) -> list[str]:
        """Nodes feeding ``node``, in source order, without repeats."""
        return list(self._index[node][0]) if node in self._index else []

    def consumers(self, node: str) -> list[str]:
        return list(self._index[node][1]) if node in self._index else []

    def internal_inputs(self, node: str) -> set[str]:
        return set(self._index[node][2]) if node in self._index else set()

    def loop_of(self, node: str) -> tuple[str, ...] | None:
        """The loop (strongly connected component) ``node`` is on, if any."""
        return self._loop_index.get(node)

    @cached_property
    def _loop_index(self) -> dict[str, tuple[str, ...]]:
        out: dict[str, tuple[str, ...]] = {}
        for loop in self.loops:
            for n in loop:
                out.setdefault(n, loop)
        return out

    def upstream(self, node: str) -> list[str]:
        """The upstream cone of ``node``: itself and every node that reaches
        it, in source order (from :meth:`upstream_masks`; ``[]`` for a node
        not in the model)."""
        return names_of(self._upstream_masks.get(node, 0), self.nodes)

    def upstream_masks(self) -> Mapping[str, int]:
        """Every node's upstream cone (:meth:`upstream`) at once, as a bit
        mask over :attr:`nodes` (bit ``i`` is ``nodes[i]``); read-only,
        built once per model.

        A search per node would cost the sum of the cones' sizes, quadratic
        along a chain (half a million names at 1000 nodes).  Here the
        strongly connected components (Tarjan's, over the producer edges)
        are taken producers first, and each component's mask is its nodes'
        bits or-ed with the masks of the producers outside it: one union
        per link, loops included, and exactly the nodes that reach each
        node (the least fixpoint: the nodes of a loop reach one another)."""
        return MappingProxyType(self._upstream_masks)

    @cached_property
    def _upstream_masks(self) -> dict[str, int]:
        index = self._index
        return upstream_bits(self.nodes, {n: index[n][0] for n in self.nodes})

    def alias(self) -> Mapping[tuple[str, str, str], str]:
        """Encoder aliases: each connected input becomes its producer's output
        symbol.  Built once per model (the calculus asks for it per node);
        read-only."""
        return MappingProxyType(self._alias)

    @cached_property
    def _alias(self) -> dict[tuple[str, str, str], str]:
        return {(l.to_node, "in", l.to_var): f"{l.from_node}.out.{l.from_var}" for l in self.links}

    def links_into(self, node: str) -> tuple[Link, ...]:
        """The links feeding ``node``, in link order (indexed once per model)."""
        return self._links_by_end[0].get(node, ())

    def readers(self, from_node: str, from_var: str) -> tuple[str, ...]:
        """The nodes reading output ``from_var`` of ``from_node``, in link order."""
        return self._links_by_end[1].get((from_node, from_var), ())

    @cached_property
    def _links_by_end(self) -> tuple[dict[str, tuple[Link, ...]], dict[tuple[str, str], tuple[str, ...]]]:
        into: dict[str, list[Link]] = {}
        read: dict[tuple[str, str], list[str]] = {}
        for l in self.links:
            into.setdefault(l.to_node, []).append(l)
            read.setdefault((l.from_node, l.from_var), []).append(l.to_node)
        return ({n: tuple(ls) for n, ls in into.items()}, {k: tuple(ns) for k, ns in read.items()})

    def to_json(self) -> ModelJson:
        return {
            "nodes": list(self.nodes),
            "connections": [l.to_json() for l in self.links],
            "environment_inputs": [{"node": n, "var": v, "type": t} for n, v, t in self.env_inputs],
            "loops": [list(l) for l in self.loops],
        }

    def cycles(self) -> list[list[str]]:
        """The elementary cycles of the node graph (an edge per connection),
        each as its node sequence starting at its first node in source order
        and following existing connections only; the closing edge goes from
        the last node back to the first.  Sorted by length, then by sequence.
        Found with Johnson's algorithm (:mod:`.cycles`), once per model: the
        check stage and the report both show them."""
        return [list(c) for c in self._cycles]

    @cached_property
    def _cycles(self) -> tuple[tuple[str, ...], ...]:
        order = {n: k for k, n in enumerate(self.nodes)}
        out = []
        for c in elementary_cycles(self.nodes, [(l.from_node, l.to_node) for l in self.links]):
            k = min(range(len(c)), key=lambda j: order[c[j]])
            out.append(c[k:] + c[:k])
        return tuple(tuple(c) for c in sorted(out, key=lambda c: (len(c), [order[n] for n in c])))

    def view(self, status: Mapping[str, str], cycles: list[list[str]] | None = None) -> ModelView:
        """:meth:`to_json` with each node's roll-up status (``pending`` when
        unknown): what the diagram and the report's system section show.
        There ``loops`` are the graph's real cycles (:meth:`cycles`, or
        ``cycles`` when the caller has them: :func:`cycles_kept`), each a
        node sequence whose consecutive pairs (and last -> first) are
        connections; the strongly connected components R4 is applied to are
        under ``loop_components``."""
        d = self.to_json()
        return {"nodes": [{"name": n, "status": status.get(n, "pending")} for n in self.nodes],
                "connections": d["connections"], "environment_inputs": d["environment_inputs"],
                "loops": self.cycles() if cycles is None else cycles, "loop_components": d["loops"]}

    @staticmethod
    def from_json(d: ModelJson) -> "SystemModel":
        return SystemModel(tuple(d["nodes"]), tuple(Link(**l) for l in d["connections"]),
                           tuple((e["node"], e["var"], e["type"]) for e in d["environment_inputs"]),
                           tuple(tuple(l) for l in d["loops"]))


def build(checked: Checked, connections: Sequence[Connection] = ()) -> SystemModel:
    """Build the system model of the checked contracts.

    Raises :class:`RclError` (located at the input's declaration) when an
    input could be fed by several nodes and the plan does not say which.
    A connection whose two ends disagree on the unit of measure does not
    stop the build: :func:`unit_diagnostics` and the check stage
    report it (:mod:`.units`).
    """
    nodes = list(checked.nodes)
    links, env, diags = _connect(checked, connections)
    diags += service_conditions(checked)
    if diags:
        raise RclError(diags)
    return SystemModel(tuple(nodes), tuple(links), tuple(env), _loops(nodes, links))


def _connect(checked: Checked, connections: Sequence[Connection]) -> tuple[list[Link], list[tuple[str, str, str]], list[Any]]:
    """The links, the environment inputs and the errors of :func:`build`'s connection search."""
    links: list[Link] = []
    env: list[tuple[str, str, str]] = []
    diags = []
    explicit = {(c.to_node, c.to_var): c for c in connections}
    outputs: dict[str, list[tuple[str, Any]]] = {}  # output name -> (node, type), in node order
    for m, other in checked.nodes.items():
        for name, ot in other.outputs.items():
            outputs.setdefault(name, []).append((m, ot))
    for n, cn in checked.nodes.items():
        for iv in cn.node.inputs:
            t = cn.inputs[iv.name]
            c = explicit.get((n, iv.name))
            if c is not None:
                links.append(Link(c.from_node, c.from_var, n, iv.name, "plan"))
                continue
            if isinstance(t, EmptyT):
                env.append((n, iv.name, str(t)))
                continue
            by_name = [m for m, ot in outputs.get(iv.name, []) if m != n and ot == t]
            via, cands = "name", [(m, iv.name) for m in by_name]
            if not cands and cn.node.links:
                via, cands = "service", service_peers(checked, n, iv.name)
            if not cands:
                via, cands = "topic", _by_topic(checked, n, iv.name)
            if len(cands) > 1:
                diags.append(error(iv.loc, f"input {iv.name!r} of {n} could be fed by {', '.join(m for m, _ in cands)}; "
                                           "name the producer under 'connections' in the plan", "E-connection"))
            elif cands:
                links.append(Link(cands[0][0], cands[0][1], n, iv.name, via))
            else:
                env.append((n, iv.name, str(t)))
    return links, env, diags


def unit_diagnostics(checked: Checked, connections: Sequence[Connection] = ()) -> list[Any]:
    """The unit errors and warnings of the connections :func:`build` finds
    (:func:`rclverify.model.system.units.connection_diagnostics`), also when the
    build fails for another reason (an ambiguous input): what ``rclverify
    check`` shows of a system's connections without running the calculus."""
    links, _, _ = _connect(checked, connections)  # the links found, whatever else fails the build
    return connection_diagnostics(checked, links)


def _by_topic(checked: Checked, node: str, var: str) -> list[tuple[str, str]]:
    cn = checked.nodes[node]
    keys = {(t.msg_type, t.key) for t in cn.node.topics
            if t.match is not None and t.match.name == var and t.match.prefix in (None, "in")}
    out = []
    for m, other in checked.nodes.items():
        if m == node:
            continue
        for t in other.node.topics:
            if t.match is not None and (t.msg_type, t.key) in keys and t.match.prefix in (None, "out") \
                    and t.match.name in other.outputs and other.outputs[t.match.name] == cn.inputs[var]:
                out.append((m, t.match.name))
    return out


def _loops(nodes: Sequence[str], links: Iterable[Link]) -> tuple[tuple[str, ...], ...]:
    """Strongly connected components with a cycle (:func:`.cycles.strongly_connected_components`:
    Tarjan's), each and all sorted."""
    succ: dict[str, set[str]] = {n: set() for n in nodes}
    for l in links:
        succ[l.from_node].add(l.to_node)
    comps = strongly_connected_components(list(nodes), {n: sorted(ws) for n, ws in succ.items()})
    return tuple(sorted(tuple(sorted(c)) for c in comps if len(c) > 1 or c[0] in succ[c[0]]))


def cycles_kept(model: SystemModel, path: Path) -> list[list[str]]:
    """``model.cycles()``, kept in ``path`` (a
    :class:`~rclverify.core.cache.store.Shelf` of kind ``system-cycles``) for the
    next run with the same nodes and connections (the key is the model's
    nodes and links as JSON).  Finding the cycles of a 1000-node system
    takes half a second, in each report task after every edit, while an
    edit seldom changes a connection (docs/scale.md).  A missing, damaged
    or foreign file is recomputed and replaced atomically; raises nothing
    for an unwritable cache (the cycles are returned anyway)."""
    from rclverify.core.cache import Shelf  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    shelf = Shelf(path, "system-cycles")
    k = shelf.key("cycles", json.dumps([list(model.nodes), [l.to_json() for l in model.links]], sort_keys=True))
    cycles: list[list[str]] = [list(c) for c in shelf.get_or_make(k, model.cycles)]
    try:
        shelf.save()
    except OSError:
        pass
    return cycles
