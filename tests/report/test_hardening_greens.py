"""Greens that were not earned (issue 35) and the assessor's bundle (issue 30).

Each test reproduces one reported way to show something as met, passed or
packed that was not, on a copy of the small three-node workspace
tests/data/requirements/stop (ObstacleDetector -> SpeedController ->
MotorDriver, Hoare evidence), with real doit, Z3 and archives:

1. a requirement whose vacuity Z3 could not decide was ``met``;
2. hand-edited requirement, health, side-condition and summary records were
   believed (``rclverify report``, ``status``, ``doit verify``);
3. ``--strict`` passed with a refuted requirement;
4. a bundle packed a report built from other inputs when only statuses were
   compared;
5. (issue 30) a ``file.py:callable`` implementation was listed as missing;
6. (issue 35, item 10) ``bundle --verify`` read every member into memory.
"""
from __future__ import annotations

import gzip
import io
import json
import shutil
import subprocess
import sys
import tarfile
import tracemalloc
from pathlib import Path

import pytest

from _restore import restored
from rclverify.report.bundle import archive
from rclverify.report.bundle.archive import verify_bundle
from rclverify.report.bundle.manifest import MANIFEST, BundleError, collect
from rclverify.cli.commands import main
from rclverify.records.sealed import read_sealed
from rclverify.model.plan.load import load_plan

DATA = Path(__file__).parent.parent / "data" / "requirements" / "stop"

FERMAT = '''  - id: FERMAT
    text: Cubes that add up to a cube leave the wheel speed as commanded.
    formal: "forall(a, b, c in NATURAL | a >= 1 and b >= 1 and a*a*a + b*b*b == c*c*c -> MotorDriver.out.wheel_speed == MotorDriver.in.speed_cmd)"
    supported_by:
      - {node: MotorDriver, guarantees: [1]}
'''


def _copy(tmp: Path, controller_m: str = "0.5", extra_requirement: str = "") -> Path:
    ws = tmp / f"stop-{controller_m}"
    shutil.copytree(DATA, ws)
    if controller_m != "0.5":
        rcl = ws / "contracts/stop.rcl"
        rcl.write_text(rcl.read_text().replace("in.distance < 0.5 ->", f"in.distance < {controller_m} ->"))
    if extra_requirement:
        plan = ws / "contracts/plan.yaml"
        plan.write_text(plan.read_text().replace("nodes:\n", extra_requirement + "nodes:\n", 1))
    return ws


def _doit(ws: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "doit", *args], cwd=ws, capture_output=True, text=True, timeout=300)


def _report(ws: Path) -> dict:
    return json.loads((ws / "reports/assurance.json").read_text())


def _reqs(ws: Path) -> dict[str, dict]:
    return {r["id"]: r for r in _report(ws)["requirements"]}


def _forge(path: Path, change) -> None:  # type: ignore[no-untyped-def]
    """Edit a JSON record by hand, as a user would (the seal left as it was)."""
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n")


def _findings(path: Path) -> list[dict]:
    d = json.loads(path.read_text())
    return d["findings"] if isinstance(d, dict) else d  # a list in the records of earlier versions


# 1 ---------------------------------------------------------------------------------------------

def test_1_a_requirement_whose_vacuity_is_undecided_is_never_met(tmp_path: Path) -> None:
    ws = _copy(tmp_path, extra_requirement=FERMAT)
    r = _doit(ws, "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    record = json.loads((ws / "artifacts/requirements/FERMAT.json").read_text())
    # Z3 proves it (the conclusion is MotorDriver's guarantee) but cannot say whether a^3 + b^3 = c^3 ever holds
    assert (record["verdict"], record["consistency"], record["vacuity"]) == ("proved", "consistent", "undecided")
    fermat = _reqs(ws)["FERMAT"]
    assert (fermat["verdict"], fermat["status"]) == ("inconclusive", "inconclusive")
    assert "vacuity undecided" in fermat["note"]
    assert "inconclusive (FERMAT)" in r.stdout and "FERMAT: met" not in r.stdout
    assert read_sealed(ws / "artifacts/requirements/FERMAT.json")[1] == ""  # the record is sealed
    assert main(["requirements", "-w", str(ws)]) == 1  # listed as not met
    assert _doit(ws, "verify", "--strict").returncode != 0


# 2 ---------------------------------------------------------------------------------------------

VACUOUS = "  guarantee( in.speed_cmd < 0 -> out.wheel_speed == 0 )\n}\n"


def test_2_records_altered_outside_rclverify_are_error_and_made_again(tmp_path: Path,
                                                                     capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path, "0.3")
    rcl = ws / "contracts/stop.rcl"  # a guarantee whose premise never holds: a contract health problem
    text = rcl.read_text()
    rcl.write_text(text[:text.rstrip().rindex("}")] + VACUOUS)
    assert _doit(ws, "verify").returncode == 0
    assert _reqs(ws)["STOP"]["verdict"] == "refuted"
    health = ws / "artifacts/health/MotorDriver.json"
    assert any(f["status"] == "problem" for f in _findings(health))
    sc = ws / "artifacts/calculus/MotorDriver.json"
    assert "no contract health problem" not in _report(ws)["summary"]["headline"]

    # the forgeries: a refuted requirement proved, the health problems ok, a side condition refuted
    _forge(ws / "artifacts/requirements/STOP.json",
           lambda d: d.update(verdict="proved", consistency="consistent", vacuity="non-vacuous", used=[]))
    _forge(health, lambda d: [f.update(status="ok") for f in (d["findings"] if isinstance(d, dict) else d)])
    _forge(sc, lambda d: [s.update(status="failed") for s in d["side_conditions"]])
    assert main(["report", "-w", str(ws)]) == 0
    report = _report(ws)
    stop = {r["id"]: r for r in report["requirements"]}["STOP"]
    assert (stop["verdict"], stop["status"]) == ("error", "error")
    assert "altered outside rclverify" in stop["note"] and "artifacts/requirements/STOP.json" in stop["note"]
    mine = [f for f in report["findings"] if f["node"] == "MotorDriver"]
    assert [f["status"] for f in mine] == ["error"] and "altered outside rclverify" in mine[0]["message"]
    assert "contract health record altered outside rclverify" in report["summary"]["headline"]
    assert {s["status"] for s in report["side_conditions"] if s["node"] == "MotorDriver"} == {"error"}
    assert not report["meta"]["strict_ok"]
    assert any("Requirement STOP is error" in p for p in report["summary"]["problems"])

    # a summary edited to look green is not shown by `rclverify status`
    capsys.readouterr()
    _forge(ws / "artifacts/report/summary.json", lambda d: d["summary"].update(status="discharged"))
    assert main(["status", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert "artifacts/report/summary.json:1:1: error: summary record altered outside rclverify" in err
    assert "discharged" not in err

    # `doit verify` does not believe them either: it makes each again, and says so
    r = _doit(ws, "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    for rel in ("artifacts/requirements/STOP.json", "artifacts/calculus/MotorDriver.json",
                "artifacts/report/summary.json"):
        assert f"{rel}: " in r.stdout and "producing it again" in r.stdout
    for rel in ("artifacts/requirements/STOP.json", "artifacts/calculus/MotorDriver.json",
                "artifacts/calculus/MotorDriver.json", "artifacts/report/summary.json"):
        assert read_sealed(ws / rel)[1] == ""
    assert _reqs(ws)["STOP"]["verdict"] == "refuted"
    assert any(f["status"] == "problem" for f in _report(ws)["findings"] if f["node"] == "MotorDriver")

    # and a requirement checked for another contract text is stale in `rclverify report`, not refuted
    rcl.write_text(rcl.read_text().replace("in.distance < 0.3 ->", "in.distance < 0.5 ->"))
    assert main(["report", "-w", str(ws)]) == 0
    stop = _reqs(ws)["STOP"]
    assert (stop["verdict"], stop["status"]) == ("stale", "stale") and "recorded verdict refuted" in stop["note"]


# 3 ---------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def met(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    """The workspace as shipped (STOP, STILL, DIST met; SAFE informal) after `doit verify --strict`: one
    run for the module; test 3 reads it, test 4 (after it) goes on from it."""
    ws = _copy(tmp_path_factory.mktemp("met"))
    return ws, _doit(ws, "verify", "--strict")


def test_3_strict_fails_on_a_formal_requirement_not_met_and_not_on_an_informal_one(
        tmp_path: Path, met: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    refuted = _copy(tmp_path, "0.3")
    r = _doit(refuted, "verify", "--strict")
    assert r.returncode != 0 and "1 formal requirement is not met (STOP)" in r.stdout + r.stderr
    # every obligation is discharged: the refuted requirement alone fails it
    assert {o["status"] for o in _report(refuted)["obligations"]} == {"discharged"}
    assert _reqs(refuted)["STOP"]["verdict"] == "refuted"

    ws, r = met
    assert r.returncode == 0, r.stdout + r.stderr
    assert _reqs(ws)["SAFE"]["verdict"] == "informal"


# 4 ---------------------------------------------------------------------------------------------

def test_4_the_bundle_refuses_a_report_built_from_other_inputs(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], met: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    # verified as shipped (nothing left to run: the plain run after --strict's does no task); edited in
    # place and put back afterwards (tests/_restore.py) for the test of the obligation list below
    with restored(met[0], tmp_path / "before") as ws:
        _the_bundle_refuses_a_report_built_from_other_inputs(ws, tmp_path, capsys)


def _the_bundle_refuses_a_report_built_from_other_inputs(ws: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert _doit(ws, "verify").returncode == 0
    out = tmp_path / "b.tar.gz"
    assert main(["bundle", "-w", str(ws), "-o", str(out)]) == 0
    # a contract edit that changes no status, then a run that stops before the report stage
    rcl = ws / "contracts/stop.rcl"
    rcl.write_text("// reviewed\n" + rcl.read_text())
    r = _doit(ws, "evidence", "requirements")
    assert r.returncode == 0, r.stdout + r.stderr
    capsys.readouterr()
    assert main(["bundle", "-w", str(ws), "-o", str(tmp_path / "stale.tar.gz")]) == 1
    err = capsys.readouterr().err
    assert "reports/assurance.json is out of date: it was built from other inputs" in err
    assert not (tmp_path / "stale.tar.gz").exists()
    assert main(["report", "-w", str(ws)]) == 0
    assert main(["bundle", "-w", str(ws), "-o", str(tmp_path / "fresh.tar.gz")]) == 0


# 5 ---------------------------------------------------------------------------------------------

PT_PLAN = """\
name: pt
contracts:
  - contracts/c.rcl
nodes:
  Agent:
    evidence:
      - backend: property_tests
        implementation: backends/property_tests/agent.py:agent
"""


def test_5_the_bundle_carries_a_property_test_implementation_named_with_its_callable(tmp_path: Path) -> None:
    files = {"contracts/plan.yaml": PT_PLAN,
             "contracts/c.rcl": "node Agent { inputs(x : INT) outputs(y : INT) guarantee(out.y == in.x) }\n",
             "backends/property_tests/agent.py": "def agent(x):\n    return {'y': x}\n"}
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    got, missing = collect(tmp_path, load_plan(tmp_path))
    assert "backends/property_tests/agent.py" in got
    assert missing == []


# 6 ---------------------------------------------------------------------------------------------

def _tar_gz(members: dict[str, bytes]) -> bytes:
    raw = io.BytesIO()
    with gzip.GzipFile(fileobj=raw, mode="wb", compresslevel=1) as gz, tarfile.open(fileobj=gz, mode="w") as tar:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    return raw.getvalue()


def test_6_bundle_verify_streams_members_and_refuses_a_huge_one_in_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import hashlib
    big = bytes(48 * 1024 * 1024)  # 48 MiB of zeros: a few kB compressed
    manifest = {"files": {"big.bin": {"sha256": hashlib.sha256(big).hexdigest(), "bytes": len(big)}}}
    good = tmp_path / "good.tar.gz"
    good.write_bytes(_tar_gz({MANIFEST: json.dumps(manifest).encode(), "big.bin": big}))
    del big
    tracemalloc.start()
    try:
        assert verify_bundle(good)["files"] == manifest["files"]
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 8 * 1024 * 1024, peak  # hashed in chunks, never held whole

    # a 3 GB member declared by a small archive (a decompression bomb) is refused from its header
    info = tarfile.TarInfo("huge.bin")
    info.size = 3 * 1024 ** 3
    bomb = tmp_path / "bomb.tar.gz"
    bomb.write_bytes(gzip.compress(info.tobuf(format=tarfile.GNU_FORMAT) + bytes(4096)))
    capsys.readouterr()
    assert main(["bundle", "--verify", str(bomb)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"{bomb}: error: huge.bin: {3 * 1024 ** 3} bytes, more than the {archive.MAX_MEMBER_BYTES} "
                   "a bundle member may have; not checked"]
    with pytest.raises(BundleError):
        verify_bundle(bomb)


def test_2_an_obligation_list_altered_outside_rclverify_is_error_and_exported_again(
        tmp_path: Path, met: tuple[Path, subprocess.CompletedProcess[str]]) -> None:
    with restored(met[0], tmp_path / "before") as ws:  # the module's verified workspace, put back afterwards
        _an_obligation_list_altered_outside_rclverify(ws)


def _an_obligation_list_altered_outside_rclverify(ws: Path) -> None:
    assert _doit(ws, "verify").returncode == 0
    listed = ws / "artifacts/obligations/SpeedController.json"
    one = ws / "artifacts/obligations/SpeedController/SpeedController.g2.hoare.speed_controller.c1.json"
    # drop an obligation from the list, and weaken one obligation's own record
    _forge(listed, lambda d: d["obligations"].pop() if isinstance(d, dict) else d.pop())
    _forge(one, lambda d: d.update(statement="true"))
    assert main(["report", "-w", str(ws)]) == 0
    report = _report(ws)
    rows = [o for o in report["obligations"] if o["node"] == "SpeedController"]
    assert [(o["id"], o["status"]) for o in rows] == [("SpeedController.obligations", "error")]
    node = next(n for n in report["nodes"] if n["name"] == "SpeedController")
    assert node["status"] == "error" and not report["meta"]["strict_ok"]
    r = _doit(ws, "verify")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "artifacts/obligations/SpeedController.json: " in r.stdout and "producing it again" in r.stdout
    assert read_sealed(one)[0]["statement"] != "true"  # exported again before its evidence ran
    rows = [o for o in _report(ws)["obligations"] if o["node"] == "SpeedController"]
    assert [o["status"] for o in rows] == ["discharged", "discharged"]


def test_2_a_grounding_altered_or_made_from_other_files_is_not_believed(tmp_path: Path) -> None:
    from rclverify.report.records import grounding
    from rclverify.app.ros_stage import GROUNDING, stage_ground
    from rclverify.stages.workspace import Workspace
    root = Path(__file__).parents[2]
    for item in ("contracts", "ros", "backends"):
        shutil.copytree(root / item, tmp_path / item)
    ws = Workspace(tmp_path, "contracts/plan.yaml")
    made = stage_ground(ws)
    assert made["counts"]["error"] == 0 and "stale" not in grounding(ws, GROUNDING)
    # the software edited after the grounding was made: stale
    script = tmp_path / "ros/rover_inspection/scripts/navigation.py"
    script.write_text(script.read_text() + "# edited\n")
    assert "made from other files" in grounding(ws, GROUNDING)["stale"]
    # a grounding error removed by hand: an error, not a clean grounding
    _forge(tmp_path / GROUNDING, lambda d: d.update(findings=[], counts={"error": 0, "warning": 0}))
    g = grounding(ws, GROUNDING)
    assert g["counts"]["error"] == 1 and "altered outside rclverify" in g["findings"][0]["message"]
