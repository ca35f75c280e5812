"""How much of a guarantee an AJPF property really checks.

A property instance covers its guarantee only partially when

* a mapping row maps a *parameterised* RCL predicate (one that mentions a
  domain variable such as ``i``) to the constant ``T`` or ``F``: the agent is
  never asked about that predicate, the plan decides it (for the case study,
  "there is no waypoint ``i + 1``" is decided by the 13-waypoint map); or
* several instances of one guarantee collapse to the same AJPF formula: the
  model check of that one formula says nothing about what distinguished the
  instances in RCL (paper lines 1396-1412 translate each instance by hand).

Both are reported on the obligation (``data["coverage"] == "partial"`` with
``data["coverage_notes"]``) and in its evidence; a property AJPF verifies is
then ``inconclusive`` for the guarantee, never ``discharged`` (the decision is
written down in docs/architecture.md, "Model-checking coverage").
"""
from __future__ import annotations

from typing import Mapping, Sequence

from . import psl
from .instantiate import Instance
from .mapping import Row


def constant_rows(rows: Sequence[Row]) -> dict[int, Row]:
    """Rows (by 0-based index) that map a predicate with domain variables to
    ``T`` or ``F``."""
    out = {}
    for r in rows:
        if not r.dom_vars:
            continue
        try:
            f = psl.parse(r.ajpf)
        except ValueError:
            continue
        if isinstance(f, psl.Const):
            out[r.index] = r
    return out


def _ranges(labels: Sequence[str]) -> str:
    return ", ".join(labels) if len(labels) <= 3 else f"{labels[0]} ... {labels[-1]} ({len(labels)} instances)"


def coverage_notes(rows: Sequence[Row], planned: Sequence[tuple[int, Instance]],
                   texts: Mapping[tuple[int, str], str]) -> dict[tuple[int, str], list[str]]:
    """Partial-coverage notes per ``(guarantee, instance label)``.

    ``planned``: ``(guarantee index, instance)`` pairs as exported;
    ``texts``: the AJPF formula text of each mapped ``(guarantee, label)``.
    Returns only the instances with something to say."""
    const = constant_rows(rows)
    notes: dict[tuple[int, str], list[str]] = {}
    for g, inst in planned:
        if inst.formula is None:
            continue
        for k in inst.rows:
            if k in const:
                r = const[k]
                notes.setdefault((g, inst.label), []).append(
                    f"mapping row {k + 1} maps `{r.rcl}` (parameterised by {', '.join(sorted(r.dom_vars))}) to the "
                    f"constant {r.ajpf}{' when ' + r.when_text if r.when_text else ''}: the agent is not checked on it")
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
