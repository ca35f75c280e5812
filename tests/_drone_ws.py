"""The drone workspaces of tests/data (a 4-node system written with `rclverify init`'s
conventions, with seeded bugs), copied and run through the whole pipeline."""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

from rclverify.app.pipeline import (Workspace, stage_check, stage_compose, stage_export, stage_health, stage_report,
                                stage_requirements, stage_run)

DATA = Path(__file__).resolve().parent / "data"


def copy(tmp_path: Path, name: str) -> Path:
    """A fresh copy of ``tests/data/<name>`` under ``tmp_path``."""
    root = tmp_path / name
    shutil.copytree(DATA / name, root)
    return root


def set_nodes(root: Path, nodes_yaml: str) -> None:
    """Replace the plan's ``nodes:`` section (the evidence entries) by ``nodes_yaml``."""
    plan = root / "contracts" / "plan.yaml"
    text = plan.read_text(encoding="utf-8")
    plan.write_text(text[:text.index("\nnodes:") + 1] + nodes_yaml, encoding="utf-8")


def verify(root: Path) -> tuple[Workspace, dict[str, Any]]:
    """Every stage of ``doit verify`` on ``root`` (check, compose, health,
    export, run, requirements, report files); the report dict."""
    ws = Workspace(root)
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
        stage_health(ws, n)
        for o in stage_export(ws, n):
            stage_run(ws, n, o.id)
    stage_requirements(ws)
    report, _ = stage_report(ws)
    return ws, report.to_json()
