"""The report's files are the ones its doit task wrote, or the task runs again (app/task_checks.py,
``TargetsAsWritten``).

``rclverify report`` renders the report from the artifacts as they are, without doit.  A user alters an
evidence record by hand, runs ``rclverify report`` (the record is ``error``: altered outside rclverify),
undoes the edit and runs ``doit verify``: every input of the report task is what it last read, and the
report kept saying ``error`` about a record that was intact again.  Found as a flaky failure of
tests/report/test_hardening_greens.py (whether the report ran again depended on another file's bytes).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from _chain import write_chain_with_evidence

from rclverify.cli.commands import main


def _doit(ws: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True, timeout=240)


def _statuses(ws: Path) -> dict[str, str]:
    report = json.loads((ws / "reports" / "assurance.json").read_text())
    return {o["id"]: o["status"] for o in report["obligations"]}


def test_a_report_rendered_outside_doit_is_rendered_again_by_the_next_run(tmp_path: Path) -> None:
    ws = write_chain_with_evidence(tmp_path / "ws")
    r = _doit(ws)
    assert r.returncode == 0, r.stdout + r.stderr
    before = _statuses(ws)
    record = sorted((ws / "artifacts" / "evidence").glob("N1.*.json"))[0]
    original = record.read_bytes()
    data = json.loads(original)
    data["status"] = "discharged" if data["status"] != "discharged" else "failed"  # a hand edit
    record.write_text(json.dumps(data))
    assert main(["report", "-w", str(ws)]) == 0
    assert _statuses(ws)[record.stem] == "error"  # altered outside rclverify
    record.write_bytes(original)  # the edit undone
    r = _doit(ws)
    assert r.returncode == 0, r.stdout + r.stderr
    assert ".  report:html" in r.stdout and ".  report:text" in r.stdout
    assert _statuses(ws) == before
    # and a run with nothing changed since is a no-op again
    r = _doit(ws)
    assert not [line for line in r.stdout.splitlines() if line.startswith(".  ")], r.stdout
