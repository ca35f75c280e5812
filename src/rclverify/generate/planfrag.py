"""The plan entries of the generated nodes (docs/generate.md, "Plan entries").

``DIR/rclverify_plan.yaml`` holds, per node, the evidence entries to put
under ``nodes:`` of the workspace's plan (docs/plan.md): a ``property_tests``
entry calling the node's ``logic.py:step`` (Python packages; the paper's
reversed workflow, lines 1864-1866: the contracts then check the
implementation written from them) and a ``monitors`` entry whose mapping,
``DIR/rclverify_mapping.yaml``, names the field of every generated topic
(docs/monitors.md, "From messages to RCL values"), with no recorded run yet:
``doit verify`` exports the node's RML and the ROSMonitoring configuration,
and a run recorded on the robot (``rclverify monitor --live``'s log) is added
under ``traces``.  Paths are relative to the workspace.
"""
from __future__ import annotations

from typing import Any, Mapping

from .nodes import NodePackage
from .wiring import wires

#: property test examples per generated node
MAX_EXAMPLES = 100


def plan_fragment(nodes: list[NodePackage], prefix: str, lang: str, rules: Mapping[str, Any] | None,
                  env: Any, marker: str) -> dict[str, str]:
    """``{path: text}`` of ``rclverify_plan.yaml`` and ``rclverify_mapping.yaml`` for the generated
    ``nodes``; ``prefix`` is the output directory relative to the workspace (``gen``)."""
    topics: dict[str, str] = {}
    for np in nodes:
        for w in wires(np, rules):
            if w.path:
                topics.setdefault(w.var_topic(np), w.path)
    pre = prefix.rstrip("/") + "/" if prefix not in ("", ".") else ""
    ctx = dict(marker=marker, nodes=nodes, pre=pre, lang=lang, max_examples=MAX_EXAMPLES,
               topics=sorted(topics.items()))
    return {"rclverify_plan.yaml": env.get_template("plan_fragment.yaml.j2").render(ctx),
            "rclverify_mapping.yaml": env.get_template("plan_mapping.yaml.j2").render(ctx)}
