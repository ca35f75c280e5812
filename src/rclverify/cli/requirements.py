"""``rclverify requirements``: each requirement with its status, on the terminal."""
from __future__ import annotations

from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:
    from rclverify.stages.workspace import Workspace

#: Verdicts that make ``rclverify requirements`` exit 1.
BAD = ("refuted", "proved from an inconsistency", "proved vacuously", "inconclusive", "stale", "error")


def show_requirements(ws: "Workspace", out: TextIO) -> int:
    """Print every requirement of ``ws`` with its verdict and status (the
    evidence roll-up of :func:`rclverify.report.build.build_report`, from
    the artifacts recorded so far), the premises a proof used and, for a
    refuted one, the counterexample node by node.  Returns the exit code:
    1 when one is refuted, proved from an inconsistency or inconclusive."""
    from rclverify.report.build import build_report
    from rclverify.report.explain import requirement_lines
    report = build_report(ws)
    bad = 0
    for r in report["requirements"]:
        out.write("".join(line + "\n" for line in requirement_lines(r)))
        bad += r["verdict"] in BAD
    return 1 if bad else 0
