"""What a backend's evidence covers of a timed guarantee.

A guarantee ``G(phi) triggered by in.x within d`` has an untimed part (``phi``
at every step, what rules R1-R4 use) and a timing part (the output follows
the trigger within ``d``; docs/decisions.md, rule D1).  Only a backend in
:data:`TIMED_BACKENDS` checks the timing part; every other backend's evidence
for a timed guarantee says so in its explanation and in
``details["timing"]``, so nothing is dropped silently.
"""
from __future__ import annotations

from typing import Mapping, TypedDict

from rclverify.lang.types import CheckedNode

class TimingNote(TypedDict):
    """``details["timing"]`` of an evidence record that checks a timed guarantee's formula only: never
    ``checked``, the guarantee's timing clause as written, and the sentence saying so."""
    checked: bool
    clause: str
    note: str


#: Backends whose evidence checks triggers and deadlines against time stamps.
TIMED_BACKENDS: frozenset[str] = frozenset({"monitors"})


def timing_of(node: CheckedNode | None, guarantee: int) -> str:
    """`` triggered by in.x within 200 ms`` of guarantee ``guarantee``
    (1-based) of ``node``, or ``""`` when it is untimed, out of range, or
    there is no checked node (a target made without contracts)."""
    if node is None:
        return ""
    gs = node.node.guarantees
    if not 1 <= guarantee <= len(gs):
        return ""
    cl = gs[guarantee - 1]
    s = f"triggered by {cl.trigger.qualified}" if cl.trigger is not None else ""
    if cl.deadline is not None:
        s += f" within {cl.deadline.amount} {cl.deadline.unit or ''}".rstrip()
    return s.strip()


def scope(backend: str, node: CheckedNode | None, guarantee: int, explanation: str,
          details: Mapping[str, object]) -> tuple[str, dict[str, object]]:
    """The explanation and details of an evidence record of ``backend`` for
    guarantee ``guarantee`` of ``node``, with the untimed-only note added when
    the guarantee is timed and the backend does not check time.  Returns
    ``(explanation, details)`` unchanged otherwise."""
    timing = timing_of(node, guarantee)
    out = dict(details)
    if not timing or backend in TIMED_BACKENDS:
        return explanation, out
    note = (f"untimed part only: {backend} checks guarantee {guarantee}'s formula, not its timing "
            f"'{timing}' (checked by the monitors against message stamps)")
    note_json: TimingNote = {"checked": False, "clause": timing, "note": note}
    out["timing"] = note_json
    return (f"{note}. {explanation}" if explanation else note), out
