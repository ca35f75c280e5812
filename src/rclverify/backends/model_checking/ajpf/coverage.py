"""How much of a guarantee an AJPF property really checks.

A property instance covers its guarantee only partially when

* a mapping row, as applied in the instance, maps an RCL predicate to a
  formula that is a constant after simplification -- ``T``, ``F``, but also
  ``~T``, ``T & T``, ``F || F`` or ``B(ag, a) || ~B(ag, a)``
  (:func:`psl.constant_value`, recorded per instance in
  ``Instance.constants``): the agent is never asked about that predicate,
  the plan decides it (for the case study, "there is no waypoint ``i + 1``"
  is decided by the 13-waypoint map); or
* several instances of one guarantee collapse to the same AJPF formula: the
  model check of that one formula says nothing about what distinguished the
  instances in RCL (paper lines 1396-1412 translate each instance by hand).

Both are reported on the obligation (``data["coverage"] == "partial"`` with
``data["coverage_notes"]``) and in its evidence; a property AJPF verifies is
then ``inconclusive`` for the guarantee, never ``discharged`` (the decision is
written down in docs/decisions.md, "Model-checking coverage").
"""
from __future__ import annotations

from typing import Mapping, Sequence

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.ajpf.instantiate import Instance
from rclverify.backends.model_checking.ajpf.mapping import Row


def _ranges(labels: Sequence[str]) -> str:
    return ", ".join(labels) if len(labels) <= 3 else f"{labels[0]} ... {labels[-1]} ({len(labels)} instances)"


def coverage_notes(rows: Sequence[Row], planned: Sequence[tuple[int, Instance]],
                   texts: Mapping[tuple[int, str], str]) -> dict[tuple[int, str], list[str]]:
    """Partial-coverage notes per ``(guarantee, instance label)``.

    ``planned``: ``(guarantee index, instance)`` pairs as exported;
    ``texts``: the AJPF formula text of each mapped ``(guarantee, label)``.
    Returns only the instances with something to say."""
    by_index = {r.index: r for r in rows}
    notes: dict[tuple[int, str], list[str]] = {}
    for g, inst in planned:
        if inst.formula is None:
            continue
        for k, value in inst.constants:
            r = by_index[k]
            param = f" (parameterised by {', '.join(sorted(r.dom_vars))})" if r.dom_vars else ""
            shown = "T" if value else "F"
            as_written = (f"the constant {shown}" if r.ajpf.strip() == shown
                          else f"`{r.ajpf.strip()}`, the constant {shown} after simplification,")
            notes.setdefault((g, inst.label), []).append(
                f"mapping row {k + 1} maps `{r.rcl}`{param} to {as_written}"
                f"{' when ' + r.when_text if r.when_text else ''}: the agent is not checked on it")
    groups: dict[tuple[int, str], list[str]] = {}
    for g, inst in planned:
        key = (g, inst.label)
        if key in texts and inst.label:
            groups.setdefault((g, texts[key]), []).append(inst.label)
    for (g, _), labels in groups.items():
        if len(labels) > 1:
            for lab in labels:
                notes.setdefault((g, lab), []).append(
                    f"instances {_ranges(labels)} of guarantee {g} collapse to one AJPF formula: what distinguishes "
                    "them in RCL is not checked")
    return notes
