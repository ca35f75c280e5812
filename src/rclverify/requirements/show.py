"""``rclverify requirements``: each requirement with its status, on the terminal."""
from __future__ import annotations

from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:
    from ..workspace import Workspace

#: Verdicts that make ``rclverify requirements`` exit 1.
BAD = ("refuted", "proved from an inconsistency", "proved vacuously", "inconclusive", "stale", "error")


def show_requirements(ws: "Workspace", out: TextIO) -> int:
    """Print every requirement of ``ws`` with its verdict and status (the
    evidence roll-up of :func:`rclverify.report.build.build_report`, from
    the artifacts recorded so far), the premises a proof used and, for a
    refuted one, the counterexample node by node.  Returns the exit code:
    1 when one is refuted, proved from an inconsistency or inconclusive."""
    from ..report.build import build_report
    report = build_report(ws)
    bad = 0
    for r in report["requirements"]:
        c = r["check"]
        out.write(f"{r['id']}: {r['verdict']} [{r['status']}]  {c.get('source') or ''}\n")
        out.write(f"  {r['text']}\n")
        if c.get("formal"):
            out.write(f"  formal: {c['formal']}\n")
        for a in c.get("assuming") or []:
            out.write(f"  assuming: {a}\n")
        out.write(f"  {r['note']}\n")
        for p in c.get("used") or []:
            out.write(f"    used: {p['label']}: {p['text']}  ({p['source']})\n")
        for p in c.get("traced_not_needed") or []:
            out.write(f"    traced, not needed: {p['label']}\n")
        for p in c.get("inconsistent_core") or []:
            out.write(f"    contradictory: {p['label']}: {p['text']}  ({p['source']})\n")
        for p in c.get("vacuity_core") or []:
            out.write(f"    premise never holds with: {p['label']}: {p['text']}  ({p['source']})\n")
        for row in c.get("counterexample") or []:
            out.write(f"    counterexample {row['node']}: " + ", ".join(f"{k} = {v}" for k, v in row["values"].items()) + "\n")
        for p in c.get("failed_to_prevent") or []:
            out.write(f"    did not prevent it: {p['label']}: {p['text']}  ({p['source']})\n")
        bad += r["verdict"] in BAD
    return 1 if bad else 0
