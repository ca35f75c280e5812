"""Skeletons a user keeps (issue 65): ``init --from-ros`` writes a node's own
inputs and outputs; a library's endpoints (here a controller's ``/tf``) are
listed apart with their reason and taken in only with
``--library-endpoints``; a service called that no scanned node serves is
``external``; and the workspace written passes both ``rclverify check`` and
``rclverify ros check``.  The packages are the self-written ones of
test_ros_controllers.py and test_ros_scan_idioms7.py."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main

import test_ros_controllers
import test_ros_scan_idioms7 as idioms7


@pytest.fixture(scope="module")
def code(tmp_path_factory) -> Path:  # type: ignore[no-untyped-def]
    root = tmp_path_factory.mktemp("code")
    for rel, text in test_ros_controllers.FILES.items():
        (root / "src" / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / "src" / rel).write_text(text)
    idioms7._package(root, "dock", {"include/dock/helpers.hpp": idioms7.HELPERS, "src/dock_node.cpp": idioms7.DOCK})
    return root


def test_own_endpoints_only_and_both_checks_pass(code: Path, tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(code)]) == 0
    err = capsys.readouterr().err
    limiter = (ws / "contracts/speed_limiter.rcl").read_text()
    assert "outputs( limited : TwistStamped, resetRes : TriggerResponse )" in limiter
    assert "//   publishes /tf (tf2_msgs/TFMessage) (" in limiter and "made by the tf library" in limiter
    assert "contracts/speed_limiter.rcl: publishes /tf (tf2_msgs/TFMessage)" in err
    plan = (ws / "contracts/plan.yaml").read_text()
    assert "  external:\n    - /speed_limiter/cmd\n    - /watched\n    - /undock\n" in plan
    assert main(["check", "-w", str(ws)] + sorted(str(p) for p in (ws / "contracts").glob("*.rcl"))) == 0
    assert main(["ros", "check", "-w", str(ws)]) == 0
    assert "grounding: 0 error(s)" in capsys.readouterr().out


def test_library_endpoints_are_opt_in(code: Path, tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    assert main(["init", str(ws), "--from-ros", str(code), "--library-endpoints"]) == 0
    limiter = (ws / "contracts/speed_limiter.rcl").read_text()
    assert "tf2_msgs/TFMessage tf matches(out.tf)" in limiter and "//   publishes /tf" not in limiter
