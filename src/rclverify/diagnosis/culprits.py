"""The members of an unsat core as culprits with source locations.

Core labels come from :mod:`rclverify.calculus.health.checks`: ``guarantee 3
(contracts/remote_inspection.rcl:72:3) at i=13``, ``environment fact 1
(contracts/plan.yaml:57:10)``, ``assumption 1 (...)``, ``premise of
guarantee 2 at i=0``.  The *victim* of a vacuity finding is its own
guarantee and premise; every other member is a culprit (an unsat core is a
set of clauses that cannot hold together: drop the victim and the rest is
what excludes it).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

_LABEL = re.compile(r"^(guarantee|assumption|environment fact) (\d+) \(([^()]*)\)(?: at (.+))?$")
_PREMISE = re.compile(r"^premise of guarantee (\d+)(?: at (.+))?$")


@dataclass(frozen=True)
class Member:
    """One member of an unsat core: ``kind`` (``guarantee``, ``assumption``,
    ``environment fact``, ``premise``), its 1-based ``index``, ``source``
    (``file:line:col`` or ``""``), the instance it was taken at (``i=13``
    or ``""``), and the formula's text and a comment above it (for a plan
    fact) when known."""

    kind: str
    index: int
    source: str
    at: str = ""
    text: str = ""
    note: str = ""

    def name(self) -> str:
        """``guarantee 3 (contracts/x.rcl:72:3) at i=13``, with the fact's text and comment."""
        out = f"{self.kind} {self.index}"
        if self.source:
            out += f" ({self.source})"
        if self.at:
            out += f" at {self.at}"
        if self.kind == "environment fact" and self.text:
            out += f" `{self.text}`" + (f" ({self.note})" if self.note else "")
        return out

    def to_json(self) -> dict[str, str | int]:
        return {"kind": self.kind, "index": self.index, "source": self.source, "at": self.at,
                "text": self.text, "note": self.note, "name": self.name()}


def parse_core(core: Sequence[str] | None, facts: Mapping[str, tuple[str, str]] | None = None) -> list[Member]:
    """The members of ``core`` (labels as above), in order and without
    repeats of the same clause (``guarantee 3`` at ``i=13`` and at ``i=12``
    stay two members).  ``facts`` maps a fact's source to (its text, the
    comment written above it in the plan)."""
    out: list[Member] = []
    for label in core or []:
        m = _LABEL.match(label.strip())
        if m:
            text, note = (facts or {}).get(m.group(3), ("", ""))
            mem = Member(m.group(1), int(m.group(2)), m.group(3), m.group(4) or "", text, note)
        else:
            p = _PREMISE.match(label.strip())
            mem = (Member("premise", int(p.group(1)), "", p.group(2) or "") if p
                   else Member("clause", 0, "", "", label.strip()))
        if mem not in out:
            out.append(mem)
    return out


def culprits(members: Sequence[Member], victim: int | None) -> list[Member]:
    """``members`` without the victim guarantee ``victim`` and its premise."""
    return [m for m in members
            if not (victim is not None and m.kind in ("guarantee", "premise") and m.index == victim)]


def plan_facts(ws: Any, node: str) -> dict[str, tuple[str, str]]:
    """``{source: (fact text, comment above it)}`` of ``node``'s plan facts;
    the comment is the run of ``#`` lines just above the fact in the plan."""
    out: dict[str, tuple[str, str]] = {}
    facts = ws.plan.facts.get(node, ())
    try:
        lines = ws.path(ws.plan.file).read_text(encoding="utf-8").splitlines()
    except OSError:
        lines = []
    for f in facts:
        note: list[str] = []
        j = f.loc.line - 2
        while 0 <= j < len(lines) and lines[j].strip().startswith("#"):
            note.insert(0, lines[j].strip().lstrip("#").strip())
            j -= 1
        out[str(f.loc)] = (f.text, " ".join(note))
    return out
