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

from rclverify.tools.generate.nodes import NodePackage
from rclverify.tools.generate.wiring import wires
from rclverify.traces.mapping import TopicRule, rule_for
from rclverify.ros.extract.model import canon_type

#: property test examples per generated node
MAX_EXAMPLES = 100


def plan_fragment(nodes: list[NodePackage], prefix: str, lang: str, rules: Mapping[str, TopicRule] | None,
                  env: Any, marker: str) -> dict[str, str]:
    """``{path: text}`` of ``rclverify_plan.yaml`` and ``rclverify_mapping.yaml`` for the generated
    ``nodes``; ``prefix`` is the output directory relative to the workspace (``gen``)."""
    topics, omitted = mapped_topics(nodes, rules)
    pre = prefix.rstrip("/") + "/" if prefix not in ("", ".") else ""
    ctx = dict(marker=marker, nodes=nodes, pre=pre, lang=lang, max_examples=MAX_EXAMPLES,
               topics=sorted(topics.items()), omitted=omitted)
    return {"rclverify_plan.yaml": env.get_template("plan_fragment.yaml.j2").render(ctx),
            "rclverify_mapping.yaml": env.get_template("plan_mapping.yaml.j2").render(ctx).rstrip("\n") + "\n"}


def mapped_topics(nodes: list[NodePackage], rules: Mapping[str, TopicRule] | None
                  ) -> tuple[dict[str, str | dict[str, str]], list[dict[str, str]]]:
    """What the generated mapping says of each topic of ``nodes``: ``(topics,
    omitted)``.  ``topics`` maps a topic to the one field path its variables
    read (a string), or, when variables of different names share the topic,
    to ``{variable name: path}`` (each variable its own field:
    docs/monitors.md, "One topic, several variables").  A standard message
    of several fields that no mapping rule of the workspace narrows is mapped
    to the field of the variable's own name when it has one
    (:func:`_field_named`); else ``omitted`` lists ``{"topic", "type",
    "var", "why"}`` for the variable, and the mapping file says so in a
    comment, naming the entry to write."""
    per: dict[str, dict[str, str]] = {}
    omitted: list[dict[str, str]] = []
    for np in nodes:
        for w in wires(np, rules):
            topic = w.var_topic(np)
            if w.path:
                per.setdefault(topic, {}).setdefault(w.name, w.path)
                continue
            end = next(e for e in np.endpoints if e.attr == w.attr)
            named = _field_named(end.ros_type, w.name)
            if named:  # the standard message has a field of the variable's name: the one it carries
                per.setdefault(topic, {}).setdefault(w.name, named)
                continue
            why = (f"{end.ros_type} has several fields and no mapping rule names the one {np.ros_name}'s {w.var} "
                   f"reads; the monitors would read its first top-level field of the variable's type, which "
                   f"may be another quantity: name it in the plan's mapping file (backends/monitors/mapping.yaml "
                   f"by default; '{topic}: {{fields: [<field>]}}') and generate again")
            item = {"topic": topic, "type": end.ros_type, "var": f"{np.ros_name}.{w.var}", "why": why}
            if item not in omitted:
                omitted.append(item)
        for var, topic in np.unwired:
            own = list(rule_for(rules, topic, var).fields) if rules else []
            if len(own) == 1:  # the workspace's mapping names its field: the monitors read it (the node does not)
                per.setdefault(topic, {}).setdefault(var.split(".", 1)[1], own[0])
                continue
            omitted.append({"topic": topic, "type": "", "var": f"{np.ros_name}.{var}", "why": (
                f"the generated node has one end per topic, which carries its first variable only: {var} is left "
                f"to the hand-written logic; to monitor it, name each variable's field in "
                f"backends/monitors/mapping.yaml ('{topic}: {{fields: {{x: [<field>], y: [<field>]}}}}', "
                f"docs/monitors.md \"One topic, several variables\")")})
    topics: dict[str, str | dict[str, str]] = {}
    for topic, by_name in per.items():
        topics[topic] = next(iter(by_name.values())) if len(by_name) == 1 else dict(sorted(by_name.items()))
    return topics, sorted(omitted, key=lambda o: (o["topic"], o["var"]))


def _field_named(ros_type: str, var: str) -> str:
    """``var`` when the standard message ``ros_type`` has a top-level field of
    that name holding one value (``range`` of ``sensor_msgs/Range``, ``x`` of
    ``geometry_msgs/Point``), else ``""``: a field named as the variable is
    the one a reader takes it to carry; any other choice is a guess."""
    from rclverify.ros.extract.interfaces import BASE_TYPES, TypeTable, field_path  # deferred: start-up (loads rclverify.core, rclverify.core.atomic and more only when called)
    typ = canon_type(ros_type)
    if not typ:
        return ""
    rt, err, arr = field_path(TypeTable(), typ, var)
    return var if err is None and not arr and (rt or "").split("<=")[0] in BASE_TYPES else ""
