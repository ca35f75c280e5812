"""The workspace boundary, checked when the plan is checked (issue 20): every
path an input names -- the plan, a review record's ``files:``, a trace
mapping's ``msg_dirs``, an ``implementation:`` module path with backslashes --
is a located error at the place that names it, before any task runs; a tool
path (``dafny: PATH``) may lie outside and is never a doit file dependency."""
from __future__ import annotations

import hashlib
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan
from rclverify.app.tasks import _inputs, act_check

from _evidence_ws import REPO, copy_workspace, plan_line

SRC = REPO / "src"


def init_ws(tmp_path: Path, sensor_entry: str = "") -> Path:
    """A fresh `rclverify init` workspace (three small nodes), with ``sensor_entry``
    (YAML lines of one evidence entry) under the Sensor node."""
    ws = tmp_path / "ws"
    assert main(["init", str(ws)]) == 0
    if sensor_entry:
        plan = ws / "contracts/plan.yaml"
        text = plan.read_text(encoding="utf-8")
        plan.write_text(text.replace("  Sensor: {}\n", "  Sensor:\n    evidence:\n" + sensor_entry), encoding="utf-8")
    return ws


def located(ws: Path, needle: str, offset: int = 0) -> str:
    line, col = plan_line(ws, needle)
    return f"contracts/plan.yaml:{line}:{col + offset}: error: "


def test_a_backslashed_implementation_path_is_refused_when_the_plan_is_checked(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Before: caught only when the node's task ran (minutes into a run); now by `compose` and doit's check.
    ws = init_ws(tmp_path, '      - backend: property_tests\n        implementation: "..\\\\..\\\\evil.py:agent"\n')
    where = located(ws, '"..', 1)  # a quoted value is located at its first character
    with pytest.raises(PlanError) as exc:
        load_plan(ws)
    assert str(exc.value.diagnostics[0]).startswith(where + "path '..\\\\..\\\\evil.py' climbs out of the workspace")
    assert main(["compose", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(where) and "Traceback" not in err
    assert "\n" + where in str(act_check(str(ws)))


@pytest.mark.parametrize("value, why", [
    ("C:\\\\evil.py:agent", "is an absolute path"),
    ("/tmp/evil.py:agent", "is an absolute path"),
    ("backends\\\\agent.py:agent", "uses '\\' as a separator"),
])
def test_declared_paths_are_checked_whatever_they_look_like(tmp_path: Path, value: str, why: str) -> None:
    ws = init_ws(tmp_path, f'      - backend: property_tests\n        implementation: "{value}"\n')
    with pytest.raises(PlanError, match="^" + located(ws, 'implementation: "', len('implementation: "')).replace(".", r"\.")) as exc:
        load_plan(ws)
    assert why in str(exc.value)


def test_a_review_record_naming_files_outside_is_a_located_error_in_the_record(tmp_path: Path) -> None:
    # Before: accepted and `discharged`; only `rclverify bundle` refused it later.
    copy_workspace(tmp_path)
    rel = "backends/review/localisation.yaml"
    data = yaml.safe_load((tmp_path / rel).read_text(encoding="utf-8"))
    data["files"] = [{"path": "/etc/passwd", "sha256": "0" * 64},
                     {"path": "../../../../etc/hostname", "sha256": "0" * 64}]
    (tmp_path / rel).write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    lines = (tmp_path / rel).read_text(encoding="utf-8").splitlines()
    first = next(i for i, l in enumerate(lines, 1) if "/etc/passwd" in l)
    second = next(i for i, l in enumerate(lines, 1) if "etc/hostname" in l)
    out = str(act_check(str(tmp_path)))
    assert f"{rel}:{first}:" in out and "reviewed file '/etc/passwd' is an absolute path" in out
    assert f"{rel}:{second}:" in out and "reviewed file '../../../../etc/hostname' climbs out" in out


def test_a_review_record_naming_a_workspace_file_still_checks(tmp_path: Path) -> None:
    copy_workspace(tmp_path)
    rel = "backends/review/localisation.yaml"
    (tmp_path / "src").mkdir()
    (tmp_path / "src/loc.py").write_text("x = 1\n", encoding="utf-8")
    data = yaml.safe_load((tmp_path / rel).read_text(encoding="utf-8"))
    data["files"] = [{"path": "src/loc.py", "sha256": hashlib.sha256(b"x = 1\n").hexdigest()}]
    (tmp_path / rel).write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    assert act_check(str(tmp_path)) is None


def test_a_trace_mapping_naming_message_directories_outside_is_located_in_the_mapping(tmp_path: Path) -> None:
    copy_workspace(tmp_path)
    shutil.copytree(REPO / "backends/monitors", tmp_path / "backends/monitors")
    mapping = tmp_path / "backends/monitors/mapping.yaml"
    text = mapping.read_text(encoding="utf-8").replace("msg_dirs: [backends/monitors/msg]",
                                                        "msg_dirs: [backends/monitors/msg, /opt/ros/share]")
    mapping.write_text(text, encoding="utf-8")
    line = next(i for i, l in enumerate(text.splitlines(), 1) if l.startswith("msg_dirs"))
    col = text.splitlines()[line - 1].index("/opt") + 1
    out = str(act_check(str(tmp_path)))
    assert (f"backends/monitors/mapping.yaml:{line}:{col}: error: message directory '/opt/ros/share' is an "
            "absolute path") in out


def test_a_tool_path_outside_the_workspace_is_allowed_and_no_file_dependency(tmp_path: Path) -> None:
    tool = shutil.which("dafny") or sys.executable  # any absolute path of an installed program
    ws = init_ws(tmp_path, f"      - backend: dafny\n        dafny: {tool}\n")
    plan = load_plan(ws)
    config = plan.evidence["Sensor"][0].config
    assert config["dafny"] == tool
    assert _inputs(config, ws, {}) == []
    # Before: doit's DependencyError on '<ws>//usr/bin/dafny'.  The implementation is missing,
    # so the entry is pending (Dafny is not run) and the run succeeds.
    r = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "verify", "-w", str(ws)], capture_output=True,
                       text=True, timeout=300, env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin"})
    assert r.returncode == 0, r.stdout + r.stderr
    assert "DependencyError" not in r.stdout + r.stderr and "1 pending" in r.stdout


@pytest.mark.parametrize("entry, message", [
    ("      - backend: dafny\n        dafny: /nonexistent/bin/dafny\n",
     "dafny: '/nonexistent/bin/dafny' does not exist (the tool is named by its path"),
    ("      - backend: dafny\n        dafny: contracts/sensor.rcl\n", "dafny: 'contracts/sensor.rcl' is not executable"),
    ("      - backend: ajpf\n        agent: a\n        mcapl_home: /nonexistent/mcapl\n",
     "mcapl_home: '/nonexistent/mcapl' is not a directory"),
])
def test_a_tool_named_by_a_path_that_is_missing_is_a_located_error(tmp_path: Path, entry: str, message: str,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    ws = init_ws(tmp_path, entry)
    key = message.split(":")[0]
    where = located(ws, f"{key}: ", len(key) + 2)
    assert main(["compose", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(where + message) and err.count("\n") == 1 and "Traceback" not in err


def test_a_tool_named_by_a_command_not_on_path_stays_pending(tmp_path: Path) -> None:
    from rclverify.app.pipeline import Workspace, stage_check, stage_export, stage_run
    ws = init_ws(tmp_path, "      - backend: dafny\n        dafny: no-such-dafny-here\n")
    assert load_plan(ws).evidence["Sensor"][0].config["dafny"] == "no-such-dafny-here"
    impl = ws / "backends/dafny/sensor.dfy"
    impl.parent.mkdir(parents=True)
    impl.write_text("// the implementation would refine the generated contract module\n", encoding="utf-8")
    w = Workspace(ws)
    stage_check(w)
    ids = [o.id for o in stage_export(w, "Sensor")]
    ev = stage_run(w, "Sensor", ids[0])
    assert ev.status == "pending" and "no 'no-such-dafny-here' on PATH" in ev.explanation


def test_contract_and_replacement_paths_with_backslashes_are_refused(tmp_path: Path) -> None:
    ws = init_ws(tmp_path)
    plan = ws / "contracts/plan.yaml"
    text = plan.read_text(encoding="utf-8")
    plan.write_text(text.replace("  - contracts/actuator.rcl", '  - "contracts\\\\actuator.rcl"').replace(
        "  Sensor: {}\n", '  Sensor:\n    replacement: "..\\\\other\\\\sensor.rcl:Sensor"\n'), encoding="utf-8")
    with pytest.raises(PlanError) as exc:
        load_plan(ws)
    messages = [d.message for d in exc.value.diagnostics]
    assert messages[0] == "path 'contracts\\\\actuator.rcl' uses '\\' as a separator; write plan paths with '/'"
    assert messages[1].startswith("path '..\\\\other\\\\sensor.rcl' climbs out of the workspace")
