"""Reading the report of an example workspace (examples/warehouse, examples/delivery): its
problem rows, their first repairs, a fix's changed lines, a node's monitored run.  Shared by
tests/examples/test_example_warehouse.py and tests/examples/test_example_delivery.py."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from rclverify.cli.commands import main


def verify(ws: Path, *extra: str) -> tuple[int, dict[str, Any]]:
    """``rclverify verify -w ws`` (and ``extra``): its exit status and reports/assurance.json."""
    rc = main(["verify", "-w", str(ws), *extra])
    return rc, json.loads((ws / "reports" / "assurance.json").read_text(encoding="utf-8"))


def rows(report: dict[str, Any]) -> dict[tuple[str, ...], dict[str, Any]]:
    """The problem rows by root-cause key."""
    return {tuple(g["key"]): g for g in report["problems"]}


def diag(report: dict[str, Any], did: str) -> dict[str, Any]:
    """The diagnosis ``did``."""
    return next(d for d in report["diagnoses"] if d["id"] == did)


def first_repair(report: dict[str, Any], key: tuple[str, ...]) -> dict[str, Any]:
    """The first repair of row ``key``, from its diagnosis."""
    ref = rows(report)[key]["repairs"][0]
    return diag(report, ref["diagnosis"])["repairs"][ref["index"]]


def changed(diff: str) -> list[str]:
    """The added and removed lines of a unified diff."""
    return [x for x in diff.splitlines() if x[:1] in "+-" and not x.startswith(("+++", "---"))]


def monitoring(report: dict[str, Any], node: str, run: str) -> dict[str, Any]:
    """The status and monitoring summary of ``node``'s evidence from the recorded run ``run``."""
    e = next(x for x in report["evidence"] if x["obligation"] == f"{node}.g0.monitors.{run}")
    return {"status": e["status"], **e["monitoring"]}
