"""The output sequences a node's interface bounds, for its realizability
check (docs/semantics.md, "Realizability over bounded output sequences").

An output of a sequence type mapped to a message field that is a bounded
sequence ``T[<=N]`` or a fixed array ``T[N]`` (the plan's mapping file and
the ``.msg`` definitions under its ``msg_dirs``, read as the property tests
read them: :func:`rclverify.backends.property_tests.at_width.carried_in`)
is bounded: at most, or exactly, ``N`` items.  The health stage passes
these bounds to :func:`rclverify.calculus.health.realizable.realizability_findings`,
and the mapping and its ``.msg`` files are then inputs of the node's health
record (:func:`bound_inputs`), so an edited definition checks it again.
Nodes without an output sequence read nothing here.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from rclverify.calculus.health.bounded import Bound
from rclverify.lang.types import SeqT

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace


def _has_sequence_output(ws: "Workspace", node: str) -> bool:
    return any(isinstance(t, SeqT) for t in ws.checked.nodes[node].outputs.values())


def output_bounds(ws: "Workspace", node: str) -> dict[str, Bound]:
    """Output name -> its :class:`Bound` for each output sequence of ``node``
    whose message field bounds it; ``{}`` when none does, when the node has
    no output sequence, or when the mapping or the definitions do not load
    (the monitors backend and the plan's checks report that)."""
    if not _has_sequence_output(ws, node):
        return {}
    from rclverify.backends.property_tests.at_width import carried_in  # deferred: start-up (yaml, rosbags)
    from rclverify.model.plan.mapping_file import plan_mapping  # deferred: as above
    _, carried = carried_in(ws.root, ws.checked.nodes[node], plan_mapping(ws.plan, node))
    return {k[len("out."):]: Bound(c.max_len, c.fixed) for k, c in sorted(carried.items())
            if k.startswith("out.") and c.seq and c.max_len is not None}


def bound_inputs(ws: "Workspace", node: str) -> list[str]:
    """The workspace-relative files :func:`output_bounds` reads for ``node``
    (the mapping file and its ``.msg`` files); ``[]`` for a node without an
    output sequence."""
    if not _has_sequence_output(ws, node):
        return []
    from rclverify.backends.property_tests.at_width import mapping_inputs  # deferred: start-up (yaml)
    from rclverify.model.plan.mapping_file import plan_mapping  # deferred: as above
    return sorted(mapping_inputs(ws.root, plan_mapping(ws.plan, node)))


__all__ = ["bound_inputs", "output_bounds"]
