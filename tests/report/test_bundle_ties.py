"""A bundle re-checked from itself: each kept query is tied to the statement
its sealed record states, each kept proof to its query (records/ties.py,
stages/crosscheck/ties.py; docs/second-solver.md, "Re-checking a bundle").

A refuted requirement re-sealed as proved with another item's query copied
in its place, and two kept proofs swapped between items, with every seal and
the manifest made again to match, fail ``bundle --verify`` and
``bundle --recheck``, naming the item; the untouched bundle passes both."""
from __future__ import annotations

import hashlib
import io
import json
import tarfile
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("cvc5", reason="cvc5 (PyPI) is a dependency of rclverify; CI installs it")

from rclverify.cli.commands import main
from rclverify.records.sealed import check_text, sealed
from rclverify.records.store import dumps
from rclverify.records.ties import query_tie, tie_query

INDEX = "artifacts/crosscheck/index.json"
REQ3 = """  - id: REQ3
    text: The output of Actuator stays at most 10.
    formal: "Actuator.out.actuator_value <= 10"
    supported_by:
      - {node: Actuator, guarantees: [1]}
"""


@pytest.fixture(scope="module")
def archive(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The bundle of `rclverify init`'s workspace with a third, refuted requirement."""
    base = tmp_path_factory.mktemp("ties")
    ws = base / "ws"
    assert main(["init", str(ws)]) == 0
    plan = ws / "contracts/plan.yaml"
    text = plan.read_text(encoding="utf-8")
    plan.write_text(text.replace("\n# Connections", "\n" + REQ3 + "\n# Connections", 1), encoding="utf-8")
    assert main(["verify", "-w", str(ws)]) in (0, 1)
    rec = json.loads((ws / "artifacts/requirements/REQ3.json").read_text(encoding="utf-8"))
    assert rec["verdict"] == "refuted" and rec["smt2"] == "artifacts/requirements/REQ3.smt2"
    out = base / "b.tar.gz"
    assert main(["bundle", "-w", str(ws), "-o", str(out)]) == 0
    return out


def _members(path: Path) -> dict[str, bytes]:
    with tarfile.open(path) as t:
        return {m.name: t.extractfile(m).read() for m in t if m.isfile()}  # type: ignore[union-attr]


def _reseal(members: dict[str, bytes], name: str, body: dict[str, Any]) -> None:
    members[name] = dumps(sealed({k: v for k, v in body.items() if k != "record_sha256"})).encode("utf-8")


def _record(members: dict[str, bytes], name: str) -> dict[str, Any]:
    body, why = check_text(members[name].decode("utf-8"))
    assert body is not None and not why
    return body


def _write(members: dict[str, bytes], out: Path) -> Path:
    """The archive ``out`` of ``members`` with its manifest made again to match every member."""
    manifest = json.loads(members["MANIFEST.json"])
    for name, data in members.items():
        if name != "MANIFEST.json":
            manifest["files"][name] = {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
    members = {**members, "MANIFEST.json": dumps(manifest).encode("utf-8")}
    with tarfile.open(out, "w:gz") as t:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
    return out


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    capsys.readouterr()
    rc = main(args)
    return rc, capsys.readouterr().err


def test_the_untouched_bundle_verifies_and_rechecks(archive: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Control: a bundle made by rclverify passes both checks; its queries and proofs end with their ties."""
    assert _run(["bundle", "--verify", str(archive)], capsys) == (0, "")
    rc, err = _run(["bundle", "--recheck", str(archive)], capsys)
    assert rc == 0, err
    members = _members(archive)
    rec = _record(members, "artifacts/requirements/REQ1.json")
    assert members["artifacts/requirements/REQ1.smt2"].decode().rstrip("\n").endswith(
        query_tie("requirement", "REQ1", rec))
    proofs = [n for n in members if n.startswith("artifacts/crosscheck/proofs/")]
    assert proofs and all(members[n].decode().rstrip("\n").rsplit("\n", 1)[1]
                          == f"; rclverify: proof of the query with sha256 {n.rsplit('/', 1)[1][:-6]}" for n in proofs)


def test_a_refuted_requirement_resealed_with_a_borrowed_query_fails(archive: Path, tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """REQ3 is refuted; the forger copies REQ1's proved query in place of REQ3's, re-seals REQ3's record
    as proved, gives the second-solver record REQ1's row for it (the same text: the same sha256 and
    proof) and the manifest: every seal and sha256 holds, and both solvers answer unsat."""
    members = _members(archive)
    members["artifacts/requirements/REQ3.smt2"] = members["artifacts/requirements/REQ1.smt2"]
    rec = _record(members, "artifacts/requirements/REQ3.json")
    rec.update(verdict="proved", reason="")
    _reseal(members, "artifacts/requirements/REQ3.json", rec)
    index = _record(members, INDEX)
    row = next(r for r in index["items"] if (r["kind"], r["id"]) == ("requirement", "REQ1"))
    index["items"].append({**row, "id": "REQ3", "smt2": "artifacts/requirements/REQ3.smt2"})
    _reseal(members, INDEX, index)
    reqs = _record(members, "artifacts/requirements/index.json")
    reqs["records"]["REQ3"] = hashlib.sha256(members["artifacts/requirements/REQ3.json"]).hexdigest()
    _reseal(members, "artifacts/requirements/index.json", reqs)
    forged = _write(members, tmp_path / "borrowed.tar.gz")
    why = ("requirement REQ3: its query artifacts/requirements/REQ3.smt2 is not the query of this requirement: "
           "it ends 'decides requirement \"REQ1\"")
    for command in ("--verify", "--recheck"):
        rc, err = _run(["bundle", command, str(forged)], capsys)
        assert rc == 1 and why in err, (command, err)
        assert "Traceback" not in err and "REQ1:" not in err.replace('"REQ1"', "")  # only the borrowing item


def test_two_swapped_proofs_fail(archive: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The proofs of REQ1's and REQ2's queries swapped between their files, the manifest made again."""
    members = _members(archive)
    rows = {r["id"]: r for r in _record(members, INDEX)["items"] if r["kind"] == "requirement"}
    one, two = rows["REQ1"]["cvc5"]["proof"], rows["REQ2"]["cvc5"]["proof"]
    assert one and two and one != two
    members[one], members[two] = members[two], members[one]
    forged = _write(members, tmp_path / "swapped.tar.gz")
    for command in ("--verify", "--recheck"):
        rc, err = _run(["bundle", command, str(forged)], capsys)
        assert rc == 1, (command, err)
        for req, proof in (("REQ1", one), ("REQ2", two)):
            assert f"requirement {req}: its proof {proof} was made for another query" in err, (command, err)


def test_two_proofs_swapped_in_the_second_solver_record_fail(archive: Path, tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """The same swap made in the second-solver record instead (each row names the other's proof), re-sealed."""
    members = _members(archive)
    index = _record(members, INDEX)
    rows = {r["id"]: r for r in index["items"] if r["kind"] == "requirement"}
    rows["REQ1"]["cvc5"]["proof"], rows["REQ2"]["cvc5"]["proof"] = \
        rows["REQ2"]["cvc5"]["proof"], rows["REQ1"]["cvc5"]["proof"]
    _reseal(members, INDEX, index)
    forged = _write(members, tmp_path / "swapped-rows.tar.gz")
    for command in ("--verify", "--recheck"):
        rc, err = _run(["bundle", command, str(forged)], capsys)
        assert rc == 1 and "requirement REQ1: its proof" in err and "is not the proof of its query" in err, err


def test_an_id_cannot_end_the_tie_comment() -> None:
    """A requirement id is plan text: written as a JSON string, a newline in it cannot start an SMT command."""
    text = tie_query("(check-sat)", "requirement", "R\n(assert false)", {"formal": "x"})
    assert text.count("\n") == 2 and "\n(assert" not in text
