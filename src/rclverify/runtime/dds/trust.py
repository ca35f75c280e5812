"""What a live DDS run's evidence cannot vouch for.

A verdict of the live monitor rests on having heard every message the node
exchanged and on being the only voice on the topics it speaks for.  Three
things break that, each found through DDS discovery or the monitor's own
bookkeeping, each a located warning while the run goes on, and each keeping
a node's evidence from reading ``discharged`` (docs/semantics.md,
"Enforcement"; docs/monitors.md, "Verdicts on the bus, enforcement, bags"):

* **another writer on a guarded topic** (``--enforce /cmd``): a node that
  was not remapped, or a second participant, publishes on ``/cmd`` beside
  the gate, so what reaches the consumers is not only what the gate
  released;
* **another writer on the verdict topic** (``/rclverify/verdict``): a
  consumer of the verdicts may read ones the monitor never gave;
* **a reader made again** while the run went on (a publisher appeared whose
  QoS the reader in place could not match): messages published meanwhile
  may have been missed, so a question may have gone unseen.

:func:`downgrade` applies them to the evidence record's nodes.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping

#: The key the verdict topic's foreign writers are recorded under.
VERDICT_KEY = "rclverify/verdict"


def reasons_for(node_topics: Iterable[str], bypass: Mapping[str, Iterable[str]],
                reader_changes: Mapping[str, int]) -> list[str]:
    """Why one node's evidence cannot be ``discharged``: ``node_topics`` the
    contract topics of the node (no leading ``/``), ``bypass`` topic key ->
    the writers found beside the monitor (``node /x`` or ``participant
    <id>``), ``reader_changes`` topic key -> how often its reader was made
    again.  Returns one sentence per reason, in a stable order."""
    mine = set(node_topics)
    out = []
    for key in sorted(bypass):
        who = sorted(set(bypass[key]))
        if not who:
            continue
        if key == VERDICT_KEY:
            out.append(f"{', '.join(who)} also wrote on /{VERDICT_KEY}: a reader of the verdicts may have read "
                       "ones this monitor never gave")
        elif key in mine:
            out.append(f"{', '.join(who)} also wrote on the guarded topic /{key}, beside the gate: its messages "
                       "reached the consumers unchecked")
    for key in sorted(reader_changes):
        n = reader_changes[key]
        if n and key in mine:
            out.append(f"the reader of /{key} was made again {n} time(s) during the run (a publisher with "
                       "QoS the reader in place could not match): messages published meanwhile may have been "
                       "missed, and with them a question")
    return out


def downgrade(nodes: list[dict[str, Any]], topics: Mapping[str, Iterable[str]], bypass: Mapping[str, Iterable[str]],
              reader_changes: Mapping[str, int]) -> None:
    """Turn each ``discharged`` node record of ``nodes`` (``{"node", "status",
    "explanation", ...}``) whose run :func:`reasons_for` finds untrustworthy
    into ``inconclusive``, the reasons added to its explanation; the
    reasons are kept under ``trust`` on every node they concern.
    ``topics``: node name -> its contract topics."""
    for n in nodes:
        why = reasons_for(topics.get(n["node"], ()), bypass, reader_changes)
        if not why:
            continue
        n["trust"] = why
        if n.get("status") == "discharged":
            n["status"] = "inconclusive"
            n["explanation"] = f"{n.get('explanation', '')}; not discharged: {'; '.join(why)}"


__all__ = ["VERDICT_KEY", "downgrade", "reasons_for"]
