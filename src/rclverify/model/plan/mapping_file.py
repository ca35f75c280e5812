"""The one trace mapping file a plan names (docs/monitors.md, "The mapping file").

The mapping file says which message field carries each contract variable
and where the message definitions are (``msg_dirs``); what a field carries
(its IDL width, its bounds) is read from it by every part that judges or
draws a field's values: the monitors over recorded and live runs, the
property tests (drawn inputs at their fields' widths), the plan's checks of
field paths and shared topics, and the ROS grounding.  All of them locate
it with :func:`plan_mapping`, so one plan reads one mapping:

1. the ``mapping`` of the evidence entry at hand, when it names one (a
   ``monitors`` entry);
2. else the ``mapping`` of the node's first ``monitors`` entry naming one;
3. else the plan's ``ros: mapping``;
4. else the ``mapping`` of the plan's first ``monitors`` entry naming one
   (nodes in plan order);
5. else none: ``None``, read as :data:`DEFAULT_MAPPING`, which may not
   exist (then there are no rules; a file the plan names must exist).
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.model.plan.model import Plan
from rclverify.model.plan.ros_section import RosSection

#: The mapping file of a workspace whose plan names none (workspace-relative).
DEFAULT_MAPPING = "backends/monitors/mapping.yaml"


def _named(config: Mapping[str, Any] | None) -> str | None:
    """The entry's ``mapping`` when it is a path (text); another value is the entry checks' to report."""
    value = config.get("mapping") if config is not None else None
    return value if isinstance(value, str) and value else None


def plan_mapping(plan: Plan | None, node: str | None = None, config: Mapping[str, Any] | None = None) -> str | None:
    """The workspace-relative mapping file the plan names for ``node``'s evidence entry ``config``
    (either may be ``None``) under ``plan`` (``None``: no plan, the entry alone), by the order of
    the module docstring; ``None`` when it names none (:data:`DEFAULT_MAPPING` then, if present).
    Never raises."""
    own = _named(config)
    if own is not None:
        return own
    if plan is None:
        return None
    if node is not None:
        for e in plan.evidence.get(node, ()):
            if e.backend == "monitors" and _named(e.config) is not None:
                return str(_named(e.config))
    ros = RosSection.of(plan.ros if isinstance(plan.ros, Mapping) else None).mapping
    if ros:
        return ros
    for entries in plan.evidence.values():
        for e in entries:
            if e.backend == "monitors" and _named(e.config) is not None:
                return str(_named(e.config))
    return None


__all__ = ["DEFAULT_MAPPING", "plan_mapping"]
