"""Issue 48's readability check on a report's counterexamples, shared by the
examples' tests (the case study in tests/report/test_pipeline_e2e.py, the delivery
robot in tests/examples/test_example_delivery.py): each failed side condition's
values short and of the nodes it involves (the cone, in context), an input
outside its node's assumption said so; each refuted requirement's values
short, of its cone, within the assumptions or with the note saying why
not; a temporal trace shown cut to what it names and what changes."""
from __future__ import annotations

from fractions import Fraction
from typing import Any

from rclverify.semantics.nicemodel import short
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.cex_cone import side_condition_view


def _short(v: str) -> bool:
    return v in ("TRUE", "FALSE", "True", "False") or not v[:1].lstrip("-").isdigit() or short(Fraction(v))


def assert_readable(report: dict[str, Any]) -> int:
    """Assert the check on ``report`` (assurance.json's dict); returns how
    many counterexamples were read."""
    read = 0
    for sc in report["side_conditions"]:
        if sc["status"] != "failed":
            continue
        read += 1
        shown = side_condition_view(SideConditionRow.of(sc)).model or {}
        assert all(_short(v) for v in shown.values()), (sc["id"], shown)
        nodes = {k.split(".")[0] for k in shown}
        ctx = sc.get("context") or {}
        if sc.get("variant") == "in context":  # traced back through the upstream cone that allowed it
            assert len(nodes) <= ctx["cone"], (sc["id"], nodes)
            for n in ctx.get("violated") or ():  # an input outside its node's assumption: said so
                assert n in sc["explanation"].split("In it the assumption of ")[1].split(" does not hold")[0]
        else:
            linked = {p.split(".")[0] for lk in sc["links"] for p in lk.split(" (")[0].split(" -> ")}
            assert nodes <= linked | set(ctx.get("violated") or ()), (sc["id"], nodes, linked)
    for q in report["requirements"]:
        if q["verdict"] != "refuted":
            continue
        c = q["check"]
        if c.get("counterexample"):
            read += 1
            vals = {f"{row['node']}.{k}": v for row in c["counterexample"] for k, v in row["values"].items()}
            assert all(_short(v) for v in vals.values()), (q["id"], vals)
            assert {row["node"] for row in c["counterexample"]} <= set(c["cone"]), q["id"]
            assert c.get("counterexample_note") or not c.get("outside_assumptions"), q["id"]
        t = c.get("temporal") or {}
        if t.get("trace"):
            read += 1
            full = {(r["node"], k) for st in t["trace"] for r in st["nodes"] for k in r["values"]}
            shown = {(r["node"], k) for st in t.get("shown") or t["trace"] for r in st["nodes"] for k in r["values"]}
            assert shown <= full and {n for n, _ in shown} <= set(c.get("cone") or {n for n, _ in full}), q["id"]
    return read
