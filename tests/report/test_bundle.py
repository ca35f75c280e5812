"""The assessor's bundle (``rclverify bundle``) and plan paths that leave the workspace."""
from __future__ import annotations

import hashlib
import io
import json
import os
import tarfile
from pathlib import Path

import pytest

from rclverify.report.bundle.archive import read_members, verify_bundle, write_bundle
from rclverify.report.bundle.manifest import MANIFEST, BundleError
from rclverify.cli.commands import main
from rclverify.records.sealed import sealed
from rclverify.records.store import dumps
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan

TOOLS = {"rclverify": "0", "z3": "4", "dafny": "not installed", "hypothesis": "6", "python": "3"}

PLAN = """\
name: mini
contracts:
  - contracts/c.rcl
nodes:
  Sensor:
    evidence:
      - backend: hoare
        program: backends/hoare/sensor.imp
        options: ["/arith:2"]
      - backend: experiment
        data: backends/experiment/trials.csv
"""


def _workspace(root: Path, plan: str = PLAN) -> Path:
    files = {
        "contracts/plan.yaml": plan,
        "contracts/c.rcl": "node Sensor { inputs(r : REAL) outputs(s : BOOL) guarantee(out.s == TRUE) }\n",
        "backends/hoare/sensor.imp": "output := green\n",
        "backends/unrelated.txt": "not named by the plan\n",
        "reports/assurance.json": json.dumps({"summary": {"status": "failed", "headline": "1 obligation: 1 failed"}}),
        "reports/assurance.html": "<html></html>\n",
        "artifacts/evidence/Sensor.g1.hoare.json": dumps(sealed(
            {"obligation": "Sensor.g1.hoare", "status": "failed",
             "input_hashes": {"backends/hoare/sensor.imp": "x", "backends/ajpf/never.log": "missing"}})),
        "artifacts/.evidence.tmp": "half-written",
        "artifacts/cache/workspace.pickle": "machine-local pickled cache: never bundled",
        "dodo.py": "# tasks\n",
    }
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text, encoding="utf-8")
    return root


def _bundle(tmp_path: Path, name: str = "b.tar.gz") -> tuple[Path, Path, dict]:
    ws = _workspace(tmp_path / "ws")
    out = tmp_path / name
    return ws, out, write_bundle(ws, load_plan(ws), out, tools=TOOLS)


def test_bundle_holds_what_an_assessor_needs_and_verifies(tmp_path: Path) -> None:
    ws, out, manifest = _bundle(tmp_path)
    assert sorted(manifest["files"]) == [
        "artifacts/evidence/Sensor.g1.hoare.json", "backends/hoare/sensor.imp", "contracts/c.rcl",
        "contracts/plan.yaml", "dodo.py", "reports/assurance.html", "reports/assurance.json"]
    assert manifest["missing"] == ["backends/experiment/trials.csv"]
    assert manifest["tools"] == dict(sorted(TOOLS.items()))
    assert manifest["reproduce"]["verify"] == "rclverify verify -w . --plan contracts/plan.yaml"
    assert manifest["verdict"] == {"status": "failed", "headline": "1 obligation: 1 failed"}
    members = read_members(out)
    assert list(members)[0] == MANIFEST and list(members)[1:] == sorted(manifest["files"])
    assert members["backends/hoare/sensor.imp"] == b"output := green\n"
    assert verify_bundle(out)["files"] == manifest["files"]
    assert oct(out.stat().st_mode & 0o777) == "0o644"


def test_bundle_is_byte_for_byte_reproducible(tmp_path: Path) -> None:
    ws, out, _ = _bundle(tmp_path)
    first = out.read_bytes()
    os.utime(ws / "contracts" / "c.rcl", (1, 1))
    write_bundle(ws, load_plan(ws), out, tools=TOOLS)
    assert out.read_bytes() == first
    with tarfile.open(out) as tar:
        assert {m.mtime for m in tar.getmembers()} == {0}


def _rewrite(src: Path, dst: Path, change: dict[str, bytes | None], extra: dict[str, bytes] | None = None) -> None:
    with tarfile.open(src) as tin, tarfile.open(dst, "w:gz") as tout:
        for m in tin.getmembers():
            data = tin.extractfile(m).read()  # type: ignore[union-attr]
            if m.name in change:
                if change[m.name] is None:
                    continue
                data = change[m.name]  # type: ignore[assignment]
            m.size = len(data)
            tout.addfile(m, io.BytesIO(data))
        for name, data in (extra or {}).items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tout.addfile(info, io.BytesIO(data))


def test_a_tampered_archive_fails_naming_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _, out, _ = _bundle(tmp_path)
    bad = tmp_path / "bad.tar.gz"
    _rewrite(out, bad, {"reports/assurance.json": b'{"summary": {"status": "discharged"}}'})
    with pytest.raises(BundleError) as exc:
        verify_bundle(bad)
    assert len(exc.value.problems) == 1 and exc.value.problems[0].startswith("reports/assurance.json: changed")
    assert main(["bundle", "--verify", str(bad)]) == 1
    err = capsys.readouterr().err
    assert f"{bad}: error: reports/assurance.json: changed (sha256 " in err and "Traceback" not in err

    _rewrite(out, bad, {"contracts/c.rcl": None}, {"backends/extra.imp": b"x"})
    with pytest.raises(BundleError) as exc:
        verify_bundle(bad)
    assert exc.value.problems == ["contracts/c.rcl: missing from the archive",
                                  "backends/extra.imp: in the archive but not in the manifest"]
    _rewrite(out, bad, {MANIFEST: None})
    with pytest.raises(BundleError, match="MANIFEST.json: missing"):
        verify_bundle(bad)
    _rewrite(out, bad, {}, {"../escape": b"x"})
    with pytest.raises(BundleError, match="unsafe"):
        verify_bundle(bad)
    (tmp_path / "junk.tar.gz").write_bytes(b"not an archive")
    assert main(["bundle", "--verify", str(tmp_path / "junk.tar.gz")]) == 1
    assert "cannot read the archive" in capsys.readouterr().err


def test_zip_bundles_verify_too(tmp_path: Path) -> None:
    _, out, manifest = _bundle(tmp_path, "b.zip")
    assert out.read_bytes()[:2] == b"PK"
    assert verify_bundle(out)["files"] == manifest["files"]


def test_cli_writes_and_checks_a_bundle(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    ws = _workspace(tmp_path / "ws")
    monkeypatch.setattr("rclverify.report.bundle.archive.tool_versions", lambda: TOOLS)
    out = tmp_path / "out.tar.gz"
    assert main(["bundle", "-w", str(ws), "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "7 file(s)" in captured.out and "backends/experiment/trials.csv: named by the plan" in captured.err
    assert main(["bundle", "--verify", str(out)]) == 0


def test_no_bundle_without_a_report_and_an_old_archive_survives(tmp_path: Path) -> None:
    ws, out, _ = _bundle(tmp_path)
    before = out.read_bytes()
    (ws / "reports" / "assurance.json").unlink()
    with pytest.raises(BundleError, match="run `doit verify` first"):
        write_bundle(ws, load_plan(ws), out, tools=TOOLS)
    assert out.read_bytes() == before
    assert [p.name for p in out.parent.iterdir() if p.name.endswith(".tmp")] == []


@pytest.mark.parametrize("value, why", [
    ("../outside.csv", "climbs out of the workspace"),
    ("/etc/passwd", "is an absolute path"),
    ("backends/../../outside.csv", "climbs out of the workspace"),
])
def test_plan_paths_leaving_the_workspace_are_located_errors(tmp_path: Path, value: str, why: str) -> None:
    ws = _workspace(tmp_path / "ws", PLAN.replace("backends/experiment/trials.csv", value))
    with pytest.raises(PlanError) as exc:
        load_plan(ws)
    d = exc.value.diagnostics[0]
    assert (d.loc.file, d.loc.line, d.loc.col) == ("contracts/plan.yaml", 11, 15)
    assert f"path {value!r} {why}" in str(d)
    assert str(d).startswith("contracts/plan.yaml:11:15: error: ")


def test_a_symlink_resolving_outside_is_refused(tmp_path: Path) -> None:
    (tmp_path / "secret.csv").write_text("1\n")
    ws = _workspace(tmp_path / "ws")
    (ws / "backends" / "experiment").mkdir(parents=True)
    (ws / "backends" / "experiment" / "trials.csv").symlink_to(tmp_path / "secret.csv")
    with pytest.raises(PlanError, match=r"resolves to .*secret.csv, outside the workspace") as exc:
        load_plan(ws)
    assert str(exc.value.diagnostics[0]).startswith("contracts/plan.yaml:11:15: error: ")


def test_contract_paths_are_checked_and_tool_options_are_not(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws", PLAN.replace("  - contracts/c.rcl", "  - ../c.rcl"))
    with pytest.raises(PlanError, match=r"plan.yaml:3:5: error: path '../c.rcl' climbs out"):
        load_plan(ws)
    # "/arith:2" (a Dafny option) and the workspace's own files are fine
    ws2 = _workspace(tmp_path / "ws2")
    assert load_plan(ws2).contracts == ("contracts/c.rcl",)


def test_cli_reports_a_plan_path_error_without_traceback(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = _workspace(tmp_path / "ws", PLAN.replace("backends/experiment/trials.csv", "../x.csv"))
    assert main(["bundle", "-w", str(ws), "-o", str(tmp_path / "o.tar.gz")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("contracts/plan.yaml:11:15: error: path '../x.csv' climbs out") and "Traceback" not in err
    assert not (tmp_path / "o.tar.gz").exists()


RECORD = "artifacts/evidence/Sensor.g1.hoare.json"


def _edited(text: bytes) -> bytes:
    """The record with its status edited to discharged, its seal left as it was."""
    return text.replace(b'"status": "failed"', b'"status": "discharged"')


def test_verify_recomputes_each_record_seal(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A record edited to discharged in the archive, the manifest edited to
    match: every file matches its manifest entry, but the record's seal is
    broken, so the bundle does not verify."""
    _, out, manifest = _bundle(tmp_path)
    members = read_members(out)
    bad_record = _edited(members[RECORD])
    assert bad_record != members[RECORD]
    manifest["files"][RECORD] = {"sha256": hashlib.sha256(bad_record).hexdigest(), "bytes": len(bad_record)}
    bad = tmp_path / "bad.tar.gz"
    _rewrite(out, bad, {RECORD: bad_record, MANIFEST: dumps(manifest).encode()})
    with pytest.raises(BundleError) as exc:
        verify_bundle(bad)
    assert exc.value.problems == [f"{RECORD}: seal broken: record altered outside rclverify: its content does not "
                                  "match the sha256 rclverify wrote with it (run `doit verify` to produce it again)"]
    assert main(["bundle", "--verify", str(bad)]) == 1
    assert f"{bad}: error: {RECORD}: seal broken" in capsys.readouterr().err
    # a record without its seal is no rclverify record either
    unsealed = json.dumps({k: v for k, v in json.loads(members[RECORD]).items() if k != "record_sha256"}).encode()
    manifest["files"][RECORD] = {"sha256": hashlib.sha256(unsealed).hexdigest(), "bytes": len(unsealed)}
    _rewrite(out, bad, {RECORD: unsealed, MANIFEST: dumps(manifest).encode()})
    with pytest.raises(BundleError, match="seal broken: record altered outside rclverify: it carries no seal"):
        verify_bundle(bad)


def test_a_json_file_rclverify_does_not_seal_is_not_a_record(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws")
    (ws / "artifacts" / "dafny").mkdir(parents=True)
    (ws / "artifacts" / "dafny" / "tool-output.json").write_text('{"verified": 3}\n')
    out = tmp_path / "b.tar.gz"
    write_bundle(ws, load_plan(ws), out, tools=TOOLS)
    assert "artifacts/dafny/tool-output.json" in verify_bundle(out)["files"]


def test_no_bundle_of_a_record_whose_seal_is_broken(tmp_path: Path) -> None:
    ws = _workspace(tmp_path / "ws")
    rec = ws / RECORD
    rec.write_bytes(_edited(rec.read_bytes()))
    with pytest.raises(BundleError) as exc:
        write_bundle(ws, load_plan(ws), tmp_path / "b.tar.gz", tools=TOOLS)
    assert exc.value.problems[0].startswith(f"{RECORD}: seal broken: record altered outside rclverify")
    assert not (tmp_path / "b.tar.gz").exists()
