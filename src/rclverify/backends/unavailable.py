"""Placeholder for backends the plan names that this version does not implement.

Every guarantee of the node becomes one obligation whose evidence is
``pending`` with the reason "backend not available": nothing is skipped
silently and nothing reads as checked.
"""
from __future__ import annotations

from ..evidence.records import Evidence, Obligation, SourceRef, make_obligation_id
from ..rcl.printer import expr_to_rcl
from .base import NodeTarget, Stopwatch, make_evidence

KINDS = {"review": "review", "experiment": "experiment", "property_tests": "testing", "monitors": "monitoring"}


class UnavailableBackend:
    """A named backend with no implementation yet (``review``, ``experiment`` ...)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.kind = KINDS.get(name, "review")

    def export(self, target: NodeTarget) -> list[Obligation]:
        """One obligation per guarantee of the node (statement = the guarantee)."""
        out = []
        for k, g in enumerate(target.node.node.guarantees, 1):
            inputs = tuple(sorted({*target.contract_files, target.plan_file,
                                   *[v for key, v in target.config.items() if key != "backend" and isinstance(v, str) and "/" in v]}))
            out.append(Obligation(
                id=make_obligation_id(target.node.name, k, self.name, f"e{target.index}"), node=target.node.name,
                guarantee=k, backend=self.name, kind=self.kind, statement=expr_to_rcl(g.formula),
                source=SourceRef(g.loc.file, g.loc.line, g.loc.col), instance=f"e{target.index}", inputs=inputs))
        return out

    def run(self, obligation: Obligation, target: NodeTarget) -> Evidence:
        """Always ``pending``: the backend is not available in this version."""
        return make_evidence(target, obligation, "pending", tool=self.name, tool_version="-", clock=Stopwatch(),
                             explanation=f"backend not available: rclverify does not implement the '{self.name}' "
                                         "backend yet; the obligation is exported and awaits it.")
