"""A derived property's two statuses over its upstream cone (the derivation and the evidence it rests on).

The rules R1-R4 derive a node's property from the contracts of its upstream
cone (the paper's composition, docs/calculus.md): the *derivation* holds
when every side condition of the cone is discharged, and the property is
*established* only when the node contracts it rests on are, which only
evidence does.  :class:`ConeEvidence` computes both for every cone of a
system with bit masks, so a 1000-node chain costs popcounts, not names.
"""
from __future__ import annotations

from functools import reduce
from operator import or_
from typing import Iterable, Mapping, Sequence

from rclverify.model.system.model import names_of
from rclverify.records.records import SEVERITY, worst
from rclverify.records.statuses import DERIVATION_OF

#: A cone's worst side-condition status as the derived property's ``derivation`` (any other: ``undecided``;
#: records/statuses.py, "Verdict and status").
DERIVATION = DERIVATION_OF
#: Most node names a derived property's note lists per status ("3 pending node contracts: A, B, C");
#: the rest are counted.  A property at the end of a 1000-node chain rests on 999 contracts: its
#: note named them all, a quadratic amount of report text nobody reads (the cone itself is the
#: system model's: ``SystemModel.upstream``).
CONE_NAMES = 10


class ConeEvidence:
    """The derivation status and the evidence status and note of the cones
    of one system: the note says which node contracts a derived property
    rests on that are not yet established ("rests on 1 failed node
    contract: RadiationSensor"), at most :data:`CONE_NAMES` per status.

    The cones of a 1000-node chain hold half a million names; grouping them
    name by name took 0.3-0.5 s of every report build (docs/scale.md,
    "The 1000-node system").  Here a cone is a bit mask over the system's nodes
    (``order``; :meth:`rclverify.model.system.model.SystemModel.upstream_masks`)
    and so is each status, so a cone's count per status is a popcount and
    the first :data:`CONE_NAMES` names of a status are its lowest bits.

    ``node_evidence`` maps node names to evidence statuses (the worst of a
    node's guarantees); ``side_conditions`` maps them to the worst status
    of their side conditions.  A node of ``order`` that either lacks is
    ``pending`` there.
    """

    def __init__(self, order: Sequence[str], node_evidence: Mapping[str, str],
                 side_conditions: Mapping[str, str] | None = None) -> None:
        self.order = list(order)
        self.bit = {n: 1 << i for i, n in enumerate(self.order)}
        self.evidence_masks = self._masks(node_evidence)
        self.side_condition_masks = self._masks(side_conditions or {})

    def _masks(self, statuses: Mapping[str, str]) -> dict[str, int]:
        masks: dict[str, int] = {}
        for n, b in self.bit.items():
            st = statuses.get(n, "pending")
            masks[st] = masks.get(st, 0) | b
        return masks

    def mask(self, cone: Iterable[str]) -> int:
        """The bit mask of the nodes ``cone`` names (``KeyError`` for a node not in ``order``)."""
        return reduce(or_, map(self.bit.__getitem__, cone), 0)

    def summary(self, mask: int) -> tuple[str, str, str]:
        """(worst side-condition status of the nodes of the cone ``mask`` --
        its derivation, ``discharged`` for an empty cone --, their worst
        evidence status, the evidence note)."""
        if not mask:
            return "discharged", "discharged", "derived; rests on no node contract"
        derivation = worst([st for st, m in self.side_condition_masks.items() if mask & m])
        counts = {st: (mask & m).bit_count() for st, m in self.evidence_masks.items() if mask & m}
        if counts.keys() == {"discharged"}:
            return derivation, "discharged", "every node contract it rests on is discharged"
        parts = []
        for st in sorted(counts, key=lambda x: -SEVERITY.get(x, 0)):
            if st == "discharged":
                continue
            n = counts[st]
            named = names_of(mask & self.evidence_masks[st], self.order, CONE_NAMES)  # the first in system order
            more = f" and {n - CONE_NAMES} more" if n > CONE_NAMES else ""
            parts.append(f"{n} {st} node contract{'s' if n != 1 else ''}: {', '.join(named)}{more}")
        return derivation, worst(list(counts)), "rests on " + "; ".join(parts)
