"""The case study's contracts as a small workspace for the language server's tests.

The rover's contracts and the plan's environment facts (which the repair of
the Agent's guarantee 3 needs: waypoints 0-12), with one requirement (REQ3), without the evidence
entries and the ROS section, so that the real stages run in about
four seconds: check, compose, health, requirements, the report with its diagnosis and SARIF
log (rclverify.app.pipeline, as `doit verify` runs them).
"""
from __future__ import annotations

import shutil
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
RCL = "contracts/remote_inspection.rcl"
PLAN = "contracts/plan.yaml"
MSG = "ros/gazebo_radiation_plugin/msg/Snapshot.msg"


def make_workspace(root: Path) -> Path:
    """Write the workspace under ``root`` (a new directory); returns ``root``."""
    (root / "contracts").mkdir(parents=True)
    shutil.copy(REPO / RCL, root / RCL)
    (root / MSG).parent.mkdir(parents=True)  # the message type the topics name (completion of its fields)
    shutil.copy(REPO / MSG, root / MSG)
    data = yaml.safe_load((REPO / PLAN).read_text(encoding="utf-8"))
    data.update(requirements=[r for r in data["requirements"] if r["id"] == "REQ3"], nodes={})
    for key in ("state", "ros"):
        data.pop(key, None)
    (root / PLAN).write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return root


def run_pipeline(root: Path, nodes: tuple[str, ...] = ()) -> None:
    """The stages of a run on ``root`` (every node's health, or ``nodes``'), then the report files."""
    from rclverify.app.pipeline import Workspace, stage_check, stage_compose, stage_health, stage_report, stage_requirements
    ws = Workspace(root)
    stage_check(ws)
    for n in ws.node_names():
        stage_compose(ws, n)
        if not nodes or n in nodes:
            stage_health(ws, n)
    stage_requirements(ws)
    stage_report(ws)  # the diagnosis stage first, then the report


async def wait_diagnostics(client, u: str, want, timeout: float):  # type: ignore[no-untyped-def]
    """The diagnostics of ``u`` once ``want(diagnostics)`` holds, waiting for the
    server's publications up to ``timeout`` seconds (an assertion error past it)."""
    import asyncio
    import time

    from lsprotocol import types as lsp
    end = time.monotonic() + timeout
    while True:
        got = list(client.diagnostics.get(u, []))
        if want(got):
            return got
        left = end - time.monotonic()
        assert left > 0, f"no diagnostics as wanted within {timeout} s; last: {[(d.code, d.message[:80]) for d in got]}"
        try:
            await asyncio.wait_for(client.wait_for_notification(lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS), left)
        except asyncio.TimeoutError:
            pass
