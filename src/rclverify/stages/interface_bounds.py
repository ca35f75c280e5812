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

from pathlib import Path

from rclverify.calculus.health.bounded import Bound
from rclverify.lang.types import CheckedNode, SeqT
from rclverify.model.plan.model import Plan


def _has_sequence_output(node: CheckedNode) -> bool:
    return any(isinstance(t, SeqT) for t in node.outputs.values())


def output_bounds(root: Path, plan: Plan, node: CheckedNode) -> dict[str, Bound]:
    """Output name -> its :class:`Bound` for each output sequence of ``node``
    (of the workspace at ``root`` under ``plan``) whose message field bounds
    it; ``{}`` when none does, when the node has no output sequence, or when
    the mapping or the definitions do not load (the monitors backend and the
    plan's checks report that)."""
    if not _has_sequence_output(node):
        return {}
    from rclverify.backends.property_tests.at_width import carried_in  # deferred: start-up (yaml, rosbags)
    from rclverify.model.plan.mapping_file import plan_mapping  # deferred: as above
    _, carried = carried_in(root, node, plan_mapping(plan, node.name))
    return {k[len("out."):]: Bound(c.max_len, c.fixed) for k, c in sorted(carried.items())
            if k.startswith("out.") and c.seq and c.max_len is not None}


def bound_inputs(root: Path, plan: Plan, node: CheckedNode) -> list[str]:
    """The workspace-relative files :func:`output_bounds` reads for ``node``
    (the mapping file and its ``.msg`` files); ``[]`` for a node without an
    output sequence."""
    if not _has_sequence_output(node):
        return []
    from rclverify.backends.property_tests.at_width import mapping_inputs  # deferred: start-up (yaml)
    from rclverify.model.plan.mapping_file import plan_mapping  # deferred: as above
    return sorted(mapping_inputs(root, plan_mapping(plan, node.name)))


__all__ = ["bound_inputs", "output_bounds"]
