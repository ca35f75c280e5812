"""Check-time validation of the plan's ``experiment`` and ``review`` entries.

Called by :func:`rclverify.plan.load.resolve`, so ``rclverify``/``doit
check`` reports a missing data or record file, a malformed record or a bad
criterion at once, located in the plan, before any evidence is touched.
"""
from __future__ import annotations

from typing import Any

from ..plan.errors import PlanError
from ..plan.load import KEY, Plan
from ..rcl import ast
from ..rcl.errors import Diagnostic
from ..rcl.types import Checked


def check_entries(plan: Plan, checked: Checked) -> list[Diagnostic]:
    """Diagnostics for every experiment/review entry of ``plan`` that does not check.
    (The two backends are imported only for a plan that has such entries:
    the experiment backend brings Z3 and matplotlib's helpers, a tenth of a
    second of every run that loads the plan.)"""
    out: list[Diagnostic] = []
    for node, entries in plan.evidence.items():
        if node not in checked.nodes:
            continue
        for e in entries:
            if e.backend not in ("experiment", "review"):
                continue

            def loc(*path: Any, key: bool = False, _e: Any = e) -> ast.Loc:
                full = ("nodes", node, "evidence", _e.index) + tuple(path)
                if key and full + (KEY,) in plan.locs:
                    return plan.locs[full + (KEY,)]
                while full and full not in plan.locs:
                    full = full[:-1]
                return plan.locs.get(full, _e.loc)
            try:
                if e.backend == "experiment":
                    from .experiment.config import read_config
                    read_config(plan.root, e.config, len(checked.nodes[node].node.guarantees), loc)
                else:
                    from .review.backend import read_record
                    read_record(plan.root, e.config, loc)
            except PlanError as exc:
                out.extend(exc.diagnostics)
    return out
