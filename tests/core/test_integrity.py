"""Nothing shown as checked that was not (issue: integrity).

Each test reproduces one way a report used to show something no check
vouched for, on the cut-down case study of ``tests/_incremental.py``, and
shows what rclverify does now:

* a plan edit (a requirement's text or tracing, the plan's name) re-renders
  the report;
* ``rclverify report`` after a contract edit shows the old contract's
  evidence, side conditions and health findings as ``stale``;
* an evidence record edited by hand is ``error: evidence altered outside
  rclverify`` (and fails ``--strict``), and ``doit verify`` produces it again;
* a run killed with SIGKILL at any point resumes: the next run executes only
  the tasks that had not finished, and its reports equal a clean run's.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import _incremental as inc
from _restore import restored


@pytest.fixture(scope="module")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    """One clean ``doit verify`` of the workspace, made once for the module: the workspace and the run.
    No test changes it (each works on a copy), so it is also the reference a resumed run must equal."""
    root = inc.make_workspace(tmp_path_factory.mktemp("base") / "ws")
    proc = inc.verify(root)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return root, proc


@pytest.fixture(scope="module")
def verified(clean_run: tuple[Path, subprocess.CompletedProcess[str]]) -> Path:
    return clean_run[0]


def _copy(verified: Path, tmp_path: Path) -> Path:
    """A copy of the verified workspace, for a test that runs no stage in it (a run in a copy re-runs
    every task: doit's state names the files by absolute path)."""
    ws = tmp_path / "ws"
    shutil.copytree(verified, ws, symlinks=True)
    return ws


def _report(ws: Path) -> dict:
    return json.loads((ws / "reports/assurance.json").read_text(encoding="utf-8"))


def _ran(proc: subprocess.CompletedProcess[str]) -> list[str]:
    """The tasks a doit run executed (its ``.  name`` lines)."""
    return [l[3:].strip() for l in proc.stdout.splitlines() if l.startswith(".  ")]


def _rclverify(ws: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rclverify.cli.commands", *args, "-w", str(ws)], capture_output=True,
                          text=True, timeout=300)


def test_a_plan_edit_re_renders_the_report(verified: Path, tmp_path: Path) -> None:
    # in place (an incremental run, as a user's), the workspace put back afterwards
    with restored(verified, tmp_path / "before") as ws:
        _a_plan_edit_re_renders_the_report(ws)


def _a_plan_edit_re_renders_the_report(ws: Path) -> None:
    inc.edit_requirement_text(ws, 7)
    inc.edit_requirement_tracing(ws, 2)  # REQ2 -> Localisation guarantee 1
    inc.edit_plan_name(ws, 9)
    proc = inc.verify(ws)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert {"report:html", "report:text"} <= set(_ran(proc))
    report = _report(ws)
    req2 = next(r for r in report["requirements"] if r["id"] == "REQ2")
    assert req2["text"] == "Each waypoint is inspected (wording 7)."
    assert [(s["node"], s["guarantee"]) for s in req2["support"]] == [("Localisation", 1)]
    assert req2["status"] == "pending"  # the review of Localisation is pending, not Agent's failure
    assert report["meta"]["workspace"] == "rover 9"
    assert "rover 9" in (ws / "reports/assurance.md").read_text(encoding="utf-8")


def test_a_contract_edit_that_changes_no_snapshot_re_renders_the_report(verified: Path, tmp_path: Path) -> None:
    """A comment after the last node changes the contract file and none of
    the snapshots made from it; the report names the files' sha256
    (``meta.inputs_sha256``), so it is rendered again, and the bundle takes
    it (found by bench/incremental_equivalence.py: the report kept the old
    sha256, `doit verify` called it up to date and the bundle refused it)."""
    with restored(verified, tmp_path / "before") as ws:
        _a_contract_edit_that_changes_no_snapshot(ws, tmp_path)


def _a_contract_edit_that_changes_no_snapshot(ws: Path, tmp_path: Path) -> None:
    snapshots = {p.name: p.read_bytes() for p in (ws / "artifacts/contracts").glob("*.json")}
    rcl = ws / "contracts/remote_inspection.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8") + "// a closing comment\n", encoding="utf-8")
    proc = inc.verify(ws)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert {p.name: p.read_bytes() for p in (ws / "artifacts/contracts").glob("*.json")} == snapshots
    assert {"report:html", "report:text"} <= set(_ran(proc))
    proc = _rclverify(ws, "bundle", "-o", str(tmp_path / "bundle.tar.gz"))
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_report_shows_evidence_of_an_edited_contract_as_stale(verified: Path, tmp_path: Path) -> None:
    with restored(verified, tmp_path / "before") as ws:
        _evidence_of_an_edited_contract_is_stale(ws)


def _evidence_of_an_edited_contract_is_stale(ws: Path) -> None:
    before = {o["id"]: o["status"] for o in _report(ws)["obligations"]}
    assert before["RadiationSensor.g1.hoare.radiation_sensor.c4"] == "discharged"
    rcl = ws / "contracts/remote_inspection.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("(250 <= in.r -> out.radiationStatus == red)",
                                                           "(250 <= in.r -> out.radiationStatus == orange)"),
                   encoding="utf-8")
    proc = _rclverify(ws, "report")  # runs no stage: only the report from what is recorded
    assert proc.returncode == 0, proc.stdout + proc.stderr
    report = _report(ws)
    after = {o["id"]: o["status"] for o in report["obligations"]}
    sensor = [k for k in after if k.startswith("RadiationSensor.")]
    assert sensor and all(after[k] == "stale" for k in sensor), after
    assert all(after[k] == before[k] for k in after if not k.startswith("RadiationSensor."))
    # Agent's side condition rests on the sensor's guarantee: decided for the old text
    sc = {s["id"]: s["status"] for s in report["side_conditions"]}
    assert sc["Agent.sc1"] == "stale" and sc["Navigation.sc1"] == "discharged"
    assert {f["status"] for f in report["findings"] if f["node"] == "RadiationSensor"} == {"stale"}
    assert not report["meta"]["strict_ok"]
    # a doit run makes everything again from the new text: nothing stale is left
    proc = inc.verify(ws)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "stale" not in {o["status"] for o in _report(ws)["obligations"]}


def test_a_check_index_that_does_not_match_its_seal_is_not_believed(verified: Path, tmp_path: Path) -> None:
    """The report takes the snapshots' hashes from check's index only while the index is sealed and
    its inputs are the current files; an index edited to list the edited file's new hash is ignored,
    the snapshots are made again and the edited node's evidence is stale."""
    from rclverify.core.cache import file_digest
    ws = _copy(verified, tmp_path)
    rcl = ws / "contracts/remote_inspection.rcl"
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("(250 <= in.r -> out.radiationStatus == red)",
                                                           "(250 <= in.r -> out.radiationStatus == orange)"),
                   encoding="utf-8")
    index = ws / "artifacts/check/index.json"
    data = json.loads(index.read_text(encoding="utf-8"))
    data["inputs"]["contracts/remote_inspection.rcl"] = file_digest(rcl)  # claims the new text was checked
    index.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    proc = _rclverify(ws, "report")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    after = {o["id"]: o["status"] for o in _report(ws)["obligations"]}
    assert after["RadiationSensor.g1.hoare.radiation_sensor.c4"] == "stale"


def test_a_hand_edited_evidence_record_is_not_believed(verified: Path, tmp_path: Path) -> None:
    with restored(verified, tmp_path / "before") as ws:
        _a_hand_edited_evidence_record_is_not_believed(ws)


def _a_hand_edited_evidence_record_is_not_believed(ws: Path) -> None:
    record = ws / "artifacts/evidence/Navigation.g1.experiment.e0.json"
    data = json.loads(record.read_text(encoding="utf-8"))
    assert data["status"] == "failed"
    data["status"] = "discharged"
    record.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    proc = _rclverify(ws, "report")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    report = _report(ws)
    row = next(o for o in report["obligations"] if o["id"] == "Navigation.g1.experiment.e0")
    assert row["status"] == "error"
    ev = next(e for e in report["evidence"] if e["obligation"] == "Navigation.g1.experiment.e0")
    assert ev["status"] == "error" and "altered outside rclverify" in ev["explanation"]
    assert any("altered outside rclverify" in p for p in report["summary"]["problems"])
    assert not report["meta"]["strict_ok"]  # --strict fails on it
    sarif = json.loads((ws / "reports/assurance.sarif").read_text(encoding="utf-8"))
    assert any(r["ruleId"] == "RCL-OBL-ERROR" and "altered outside rclverify" in r["message"]["text"]
               for r in sarif["runs"][0]["results"])
    # doit verify does not believe it either: it produces the evidence again
    proc = inc.verify(ws)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "evidence:Navigation.g1.experiment.e0" in _ran(proc)
    assert "altered outside rclverify" in proc.stdout
    assert json.loads(record.read_text(encoding="utf-8"))["status"] == "failed"


def test_bundle_refuses_a_report_that_calls_stale_evidence_anything_else(verified: Path, tmp_path: Path) -> None:
    ws = _copy(verified, tmp_path)
    prog = ws / "backends/hoare/radiation_sensor.imp"
    prog.write_text(prog.read_text(encoding="utf-8").replace("(input < 120)", "(input < 119)"), encoding="utf-8")
    out = tmp_path / "b.tar.gz"
    proc = _rclverify(ws, "bundle", "-o", str(out))
    assert proc.returncode == 1 and not out.exists()
    assert "reports/assurance.json is out of date" in proc.stderr and "-> stale)" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert _rclverify(ws, "report").returncode == 0  # the report now says stale: the bundle may hold it
    proc = _rclverify(ws, "bundle", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    assert out.is_file()


def test_a_record_without_a_seal_is_not_believed(verified: Path, tmp_path: Path) -> None:
    ws = _copy(verified, tmp_path)
    record = ws / "artifacts/evidence/Navigation.g1.experiment.e0.json"
    data = json.loads(record.read_text(encoding="utf-8"))
    del data["record_sha256"]
    record.write_text(json.dumps(data), encoding="utf-8")
    assert _rclverify(ws, "report").returncode == 0
    row = next(o for o in _report(ws)["obligations"] if o["id"] == "Navigation.g1.experiment.e0")
    assert row["status"] == "error"


# -- resumable runs --------------------------------------------------------------------------------

def _run_and_kill(ws: Path, at: str, timeout: float = 120) -> list[str]:
    """Start ``doit verify`` in ``ws`` and SIGKILL its process group when it
    starts the task ``at``; return the tasks it started (``at`` last).  When
    the run ends before that, it is not killed."""
    env = {**os.environ, "PYTHONHASHSEED": "0", "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "doit", "verify"], cwd=ws, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, start_new_session=True)
    started: list[str] = []
    deadline = time.monotonic() + timeout
    try:
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith(".  "):
                started.append(line[3:].strip())
                if started[-1] == at:
                    os.killpg(proc.pid, signal.SIGKILL)
                    break
            assert time.monotonic() < deadline, "doit verify did not reach the kill point in time"
    finally:
        if proc.poll() is None:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        proc.wait(timeout=30)
        if proc.stdout is not None:
            proc.stdout.close()
    return started


def test_a_killed_run_resumes_where_it_stopped(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                              clean_run: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    """SIGKILL at five points of one workspace's runs (each run resumes the
    last and is killed further on), then a run to the end: each run executes
    only the tasks that had not finished, and the reports equal a clean run's
    (the module's clean run, of a workspace made the same way)."""
    reference, full = clean_run
    every = _ran(full)
    ws = inc.make_workspace(tmp_path / "killed" / "ws")
    finished: set[str] = set()
    evidence = [t for t in every if t.startswith("evidence:")]
    # kill points: checking, a node task, an evidence task, the first and the last report task
    points = ["check", next(t for t in every if t.startswith("node:")), evidence[len(evidence) // 2],
              "report:html", "report:text"]
    for at in points:
        started = _run_and_kill(ws, at)
        assert started[-1] == at, started
        assert not set(started) & finished, f"re-ran finished tasks: {set(started) & finished}"
        finished.update(started[:-1])  # a serial run: every task before the killed one finished
        with capsys.disabled():
            print(f"\nkilled at {at}: this run executed {len(started)} task(s), "
                  f"{len(finished)}/{len(every)} finished so far")
    last = inc.verify(ws)
    assert last.returncode == 0, last.stdout + last.stderr
    again = _ran(last)
    assert not set(again) & (finished - {"verify"}), f"re-ran finished tasks: {set(again) & finished}"
    assert len(again) <= len(every) - len(finished - {"verify"})
    with capsys.disabled():
        print(f"the run to the end executed {len(again)} task(s) of {len(every)}")
    a, b = inc.report_files(ws), inc.report_files(reference)
    assert a.keys() == b.keys()
    for name in a:
        assert a[name] == b[name], name + inc._first_difference(a[name], b[name])
