"""Confidence over a mixed-method argument (docs/confidence.md).

The paper leaves open "the level of confidence we can have in a system
that has been verified using a mixture of methods; particularly how
confidence can be calculated for more complex systems with loops in the
information flow" (lines 1876-1877).  This module answers it with one
conservative calculus over doubts (``doubt = 1 - confidence``; each
evidence kind's doubt is :data:`.strength.DOUBT`):

C0  a failed obligation is counter-evidence: it defeats its guarantee
    (doubt 1), whatever else supports it;
C1  a guarantee's doubt is the least doubt of its evidence legs (one leg per
    evidence entry, its doubt the C2 sum over the entry's obligations; the
    strongest leg; legs are not assumed independent, so several legs earn
    no extra credit: Littlewood and Wright, IEEE TSE 33(5), 2007); 1 without
    discharged evidence;
C2  a claim resting on premises ``P`` has doubt ``min(1, sum of the
    doubts of P)``: the Frechet (Boole) bound, which holds whatever the
    dependence between the premises (Bishop, Bloomfield, Littlewood et al.,
    IEEE TSE 37(5), 2011);
C3  a node's claim rests on its guarantees and its side conditions;
C4  a derived property of node ``n`` (rules R1-R3 compose it from the
    nodes upstream) rests on the premises of every node of ``n``'s cone,
    the least fixpoint of ``cone(n) = {n} + cone(p) for each producer p``;
    around a loop (R4) the fixpoint is reached once the loop's nodes are
    in, and each premise counts once;
C5  a proved requirement rests on its own proof (one or two solvers), the
    guarantees its proof used, their nodes' side conditions and the
    declared premises it used (``assumed``); a requirement not proved has
    doubt 1.

The premise with the largest doubt is what *limits* a claim; the report
names it ("REQ2 rests on tested-only evidence for Navigation guarantee 1").
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import chain
from typing import Iterable, Mapping, Sequence

from rclverify.core.extras import installed
from rclverify.model.system.cycles import upstream_bits


@dataclass(frozen=True)
class Premise:
    """One leaf of the argument: ``label`` (``"Navigation guarantee 1"``),
    ``kind`` (a strength kind, :data:`.strength.KINDS`), ``doubt`` in [0, 1]."""

    label: str
    kind: str
    doubt: float


@dataclass(frozen=True)
class Claim:
    """A claim's ``doubt`` (C2 over its premises), its ``confidence``
    (``1 - doubt``) and the premise that ``limits`` it (``None`` without
    premises)."""

    doubt: float
    confidence: float
    limits: Premise | None


def guarantee_premise(label: str, legs: Sequence[tuple[str, float]]) -> Premise:
    """C1: the premise of a guarantee from its evidence ``legs`` (``(kind,
    doubt)`` each): the leg of least doubt; ``assumed`` with doubt 1
    without legs."""
    if not legs:
        return Premise(label, "assumed", 1.0)
    kind, doubt = min(legs, key=lambda kd: kd[1])
    return Premise(label, kind, doubt)


def claim(premises: Iterable[Premise]) -> Claim:
    """C2: the claim resting on ``premises`` (each counted once, by label)."""
    seen: dict[str, Premise] = {}
    for p in premises:
        seen.setdefault(p.label, p)
    doubt = min(1.0, sum(p.doubt for p in seen.values()))
    limits = max(seen.values(), key=lambda p: (p.doubt, p.label), default=None)
    return Claim(round(doubt, 9), round(1.0 - doubt, 9), limits)


def cones(producers: Mapping[str, Iterable[str]]) -> dict[str, frozenset[str]]:
    """C4's cones: for every node of ``producers`` (node -> its producer
    nodes), the least fixpoint ``cone(n) = {n} + cone(p)`` (loops
    included): the nodes with a path to ``n``, and ``n``.  Read off
    :func:`rclverify.model.system.cycles.upstream_bits` (one union per link
    over the strongly connected components; a loop's nodes share one cone).
    Iterating the fixpoint over the nodes
    until no cone grew took 1.4 CPU s of each report task at 1000 nodes
    (docs/scale.md); networkx's condensation does the same in
    0.1 s, plus 0.1 s to import it in every report process."""
    nodes = sorted(set(producers) | {p for ps in producers.values() for p in ps})
    bits = upstream_bits(nodes, {n: list(producers.get(n, ())) for n in nodes})
    sets: dict[int, frozenset[str]] = {}  # one set per distinct cone: a loop's nodes share theirs
    for b in set(bits.values()):
        sets[b] = frozenset(nodes[i] for i in range(b.bit_length()) if b >> i & 1)
    return {n: sets[bits[n]] for n in nodes}


def node_claims(own: Mapping[str, Sequence[Premise]]) -> dict[str, Claim]:
    """C3: each node's claim from its ``own`` premises (guarantees and side conditions)."""
    return {n: claim(ps) for n, ps in own.items()}


#: Nodes from which :func:`derived_claims` reads its cones as bit masks over numpy arrays (below, numpy's
#: import costs more than it saves).
VECTOR_FROM = 64


def derived_claims(own: Mapping[str, Sequence[Premise]], producers: Mapping[str, Iterable[str]], *,
                   vector_from: int = VECTOR_FROM) -> dict[str, Claim]:
    """C4: each node's derived property, resting on the premises of its cone
    (``own``: node -> its premises; ``producers``: node -> its producer
    nodes).  Along a chain the cones hold N*N/2 premises in all; when no
    label is shared (each premise then counts once as it stands), each claim
    is read from per-node doubts and limits instead of through :func:`claim`:
    the doubts summed in the same order (the same floating-point sum) and the
    limit the largest of the nodes' own (``(doubt, label)`` keys are then
    distinct, so the largest is one premise whatever the order).  From
    ``vector_from`` nodes on, the cones are bit masks over the nodes in
    sorted order and each cone's doubts are gathered in that order by numpy
    (:func:`_vector_claims`: sorting each cone's names was most of the
    report's time at 5000 nodes; without numpy, the ``fast`` extra, the
    per-node path).  Equal to :func:`claim` over the
    cone (``tests/report/test_confidence.py``)."""
    labels = [p.label for ps in own.values() for p in ps]
    reads = {n: list(producers.get(n, ())) for n in own}
    if len(labels) == len(set(labels)) and len(own) >= vector_from and installed("numpy"):
        return _vector_claims(own, reads)
    cone = cones(reads)
    if len(set(labels)) != len(labels):
        return {n: claim(p for m in sorted(cone[n]) for p in own.get(m, ())) for n in own}
    doubts = {m: tuple(p.doubt for p in ps) for m, ps in own.items()}
    top = {m: max(ps, key=lambda p: (p.doubt, p.label)) for m, ps in own.items() if ps}
    out: dict[str, Claim] = {}
    for n in own:
        members = sorted(cone[n])
        doubt = min(1.0, sum(chain.from_iterable(doubts.get(m, ()) for m in members)))
        limits = max((top[m] for m in members if m in top), key=lambda p: (p.doubt, p.label), default=None)
        out[n] = Claim(round(doubt, 9), round(1.0 - doubt, 9), limits)
    return out


def _vector_claims(own: Mapping[str, Sequence[Premise]], producers: Mapping[str, Sequence[str]]) -> dict[str, Claim]:
    """:func:`derived_claims` (no label shared) with each cone a bit mask
    (a Python ``int``, bit ``i`` the ``i``-th node in sorted order:
    :func:`~rclverify.model.system.cycles.upstream_bits`), and each
    node's premises' doubts a run of one array in that order: a cone's
    doubts are the runs its mask selects, in sorted node order, summed by
    Python's ``sum`` as the per-node path sums them; its limit is the
    greatest ``(doubt, label)`` of its nodes' own, found as the highest
    rank of the nodes' tops sorted once."""
    from rclverify.core.numeric import np  # deferred: optional or conditional (large systems only: VECTOR_FROM)
    nodes = sorted(set(producers) | {p for ps in producers.values() for p in ps})
    rank = {m: i for i, m in enumerate(nodes)}
    bits = upstream_bits(nodes, {m: list(producers.get(m, ())) for m in nodes})
    counts = np.array([len(own.get(m, ())) for m in nodes], dtype=np.int64)
    flat = np.array([p.doubt for m in nodes for p in own.get(m, ())], dtype=np.float64)
    tops = sorted(((max(own[m], key=lambda p: (p.doubt, p.label)), rank[m]) for m in nodes if own.get(m)),
                  key=lambda t: (t[0].doubt, t[0].label))
    top_rank = np.full(len(nodes), -1, dtype=np.int64)  # each node's top's place among all tops, -1 without one
    for k, (_, r) in enumerate(tops):
        top_rank[r] = k
    size = (len(nodes) + 7) // 8
    out: dict[str, Claim] = {}
    for n in own:
        mask = np.unpackbits(np.frombuffer(bits[n].to_bytes(size, "little"), dtype=np.uint8),
                             bitorder="little")[:len(nodes)].astype(bool)
        doubt = min(1.0, sum(flat[np.repeat(mask, counts)].tolist()))
        best = int(top_rank[mask].max())
        out[n] = Claim(round(doubt, 9), round(1.0 - doubt, 9), tops[best][0] if best >= 0 else None)
    return out


def requirement_claim(proved: bool, proof: Premise, used: Sequence[Premise]) -> Claim:
    """C5: a requirement's claim; doubt 1 (limited by its own proof) when not proved."""
    if not proved:
        return Claim(1.0, 0.0, Premise(proof.label, proof.kind, 1.0))
    return claim([proof, *used])
