"""The second solver (issue 50): every discharging Z3 query decided again by
cvc5 from its SMT-LIB2 text, with a checked proof; a disagreement is never
proved; ``bundle --recheck`` re-decides a bundle's queries from it alone."""
from __future__ import annotations

import io
import json
import tarfile
from pathlib import Path

import pytest

pytest.importorskip("cvc5", reason="cvc5 (PyPI) is a dependency of rclverify; CI installs it")

from rclverify.cli.commands import main
from rclverify.stages.crosscheck.cvc5_decide import decide
from rclverify.stages.crosscheck.stage import agreement, stage_crosscheck

SAT_SCRIPT = "(declare-fun x () Real)\n(assert (> x 1.0))\n(check-sat)\n"


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("second") / "ws"
    assert main(["init", str(root)]) == 0
    assert main(["verify", "-w", str(root)]) in (0, 1)
    return root


def _report(root: Path) -> dict:
    return json.loads((root / "reports/assurance.json").read_text())


def test_every_proof_has_both_solvers_and_a_checked_proof(ws: Path) -> None:
    r = _report(ws)
    scs = [sc for sc in r["side_conditions"] if sc["status"] == "discharged"]
    reqs = [q for q in r["requirements"] if q.get("check", q).get("solvers")]
    assert scs and len(reqs) == 2
    for s in [sc["solvers"] for sc in scs] + [q["check"]["solvers"] for q in reqs]:
        assert s["agreement"] == "two solvers", s
        assert s["cvc5"]["answer"] == "unsat" and s["cvc5"]["proof_checked"] is True
        proof = (ws / s["proof"]).read_text()
        assert proof.strip().startswith("(") and len(proof) > 100
    index = json.loads((ws / "artifacts/crosscheck/index.json").read_text())
    assert index["solver"]["name"] == "cvc5" and index["counts"] == {"two solvers": len(index["items"])}


def test_a_planted_wrong_proof_reads_inconclusive(ws: Path, tmp_path: Path) -> None:
    import shutil
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    # the record says Z3 proved REQ1 and discharged Actuator.sc1; their queries are in fact satisfiable
    (root / "artifacts/requirements/REQ1.smt2").write_text(SAT_SCRIPT)
    (root / "artifacts/calculus/Actuator.sc1.smt2").write_text(SAT_SCRIPT)
    stage_crosscheck(root, ["Sensor", "Controller", "Actuator"])
    assert main(["report", "-w", str(root)]) in (0, 1)
    r = _report(root)
    sc = next(sc for sc in r["side_conditions"] if sc["id"] == "Actuator.sc1")
    assert sc["status"] == "inconclusive" and sc["solvers"]["agreement"] == "disagree"
    assert "Z3 answered unsat, cvc5 sat" in sc["explanation"]
    req = next(q for q in r["requirements"] if q["id"] == "REQ1")
    assert req["verdict"] == "inconclusive", req["verdict"]
    assert "second solver does not confirm it" in req["note"]
    # the argument shows the disagreement as a defeater (GSN dialectic extension) of the claims it undermines
    arg = json.loads((root / "reports/argument.json").read_text())
    els = {e["id"]: e for e in arg["elements"]}
    assert els["CSn-solvers.Actuator.sc1"]["challenges"] == ["G-sc.Actuator.sc1"]
    assert els["G-sc.Actuator.sc1"]["defeated"] is True and els["G-REQ1"]["defeated"] is True
    assert "defeated: true" in (root / "reports/argument.gsn.yaml").read_text()
    assert main(["verify", "-w", str(root), "--strict"]) == 1


def test_a_requirements_side_queries_are_decided_by_both_and_a_disagreement_is_inconclusive(
        ws: Path, tmp_path: Path) -> None:
    import shutil
    r = _report(ws)
    req2 = next(q for q in r["requirements"] if q["id"] == "REQ2")["check"]
    for side, answer in (("consistency", "sat"), ("vacuity", "sat")):
        s = req2[f"{side}_solvers"]
        assert s["agreement"] == "two solvers" and s["cvc5"]["answer"] == answer, (side, s)
        assert s["smt2"] == f"artifacts/requirements/REQ2.{side}.smt2"
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    # the record says Z3 found a model of REQ2's premise; its stored query is in fact unsatisfiable
    (root / "artifacts/requirements/REQ2.vacuity.smt2").write_text(
        "(declare-fun x () Real)\n(assert (and (> x 1.0) (< x 0.0)))\n(check-sat)\n")
    stage_crosscheck(root, ["Sensor", "Controller", "Actuator"])
    assert main(["report", "-w", str(root)]) in (0, 1)
    req = next(q for q in _report(root)["requirements"] if q["id"] == "REQ2")
    assert req["verdict"] == "inconclusive" and req["check"]["vacuity_solvers"]["agreement"] == "disagree"
    assert "second solver does not agree: Z3 answered sat, cvc5 unsat" in req["note"]
    assert "Vacuity (non-vacuous): disagree" in (root / "reports/assurance.md").read_text()


def test_cvc5_unknown_on_a_proof_is_inconclusive() -> None:
    hard = ("(declare-fun x () Int)(declare-fun y () Int)(declare-fun z () Int)"
            "(assert (and (> x 0) (> y 0) (> z 0) (= (+ (* x x x) (* y y y)) (* z z z))))(check-sat)")
    d = decide(hard, rlimit=2_000)
    assert d.answer == "unknown"
    row = {"answer": d.answer, "reason": d.reason, "proof_checked": d.proof_checked, "version": d.version}
    assert agreement("unsat", row)[0] == "inconclusive"
    assert agreement("sat", row)[0] == "one solver"  # a witness of Z3's stands alone
    assert agreement("unsat", {"answer": "error", "reason": "x"})[0] == "one solver"
    assert agreement("unsat", {"answer": "unsat", "proof_checked": False})[0] == "disagree"
    assert agreement("unsat", None)[0] == "one solver"


def test_a_rejected_script_is_an_error_never_an_answer() -> None:
    assert decide("(assert (> x 0))(check-sat)").answer == "error"
    assert decide("(declare-fun x () Int)").answer == "error"
    d = decide("(declare-fun x () Int)(assert (and (> x 0) (< x 0)))(check-sat)")
    assert d.answer == "unsat" and d.proof_checked and d.proof
    # a side condition decided in context: its local query (sat), `(reset)`, then the query in context (unsat);
    # the verdict rests on the last, which cvc5 decides with its proof (cvc5 stops proofs at a reset)
    ctx = ("(declare-fun x () Real)\n(assert (> x 1.0))\n(check-sat)\n(reset)\n"
           "(declare-fun x () Real)\n(assert (and (> x 1.0) (< x 0.0)))\n(check-sat)\n")
    d = decide(ctx)
    assert d.answer == "unsat" and d.proof_checked


def _rewrite(archive: Path, out: Path, name: str, edit) -> None:
    with tarfile.open(archive) as t:
        members = [(m, t.extractfile(m).read() if m.isfile() else None) for m in t.getmembers()]
    with tarfile.open(out, "w:gz") as t:
        for m, data in members:
            if m.name == name:
                data = edit(data)
                m.size = len(data)
            t.addfile(m, io.BytesIO(data) if data is not None else None)


def test_bundle_recheck(ws: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    archive = tmp_path / "b.tar.gz"
    assert main(["bundle", "-w", str(ws), "-o", str(archive)]) == 0
    capsys.readouterr()
    assert main(["bundle", "--recheck", str(archive)]) == 0
    assert "every answer agrees" in capsys.readouterr().out
    edited = tmp_path / "edited.tar.gz"  # a bound of the stored query changed: 100 -> 1000 in a premise
    _rewrite(archive, edited, "artifacts/requirements/REQ1.smt2",
             lambda b: b.replace(b"(<= Actuator.out.actuator_value (to_real 100))",
                                 b"(<= Actuator.out.actuator_value (to_real 1000))", 1))
    assert main(["bundle", "--recheck", str(edited)]) == 1
    err = capsys.readouterr().err
    assert "requirement REQ1: its query artifacts/requirements/REQ1.smt2 was edited" in err


def test_bundle_recheck_names_an_edited_verdict(ws: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    archive = tmp_path / "b.tar.gz"
    assert main(["bundle", "-w", str(ws), "-o", str(archive)]) == 0
    edited = tmp_path / "edited.tar.gz"
    _rewrite(archive, edited, "artifacts/requirements/REQ2.json",
             lambda b: b.replace(b'"proved"', b'"refuted"', 1))
    capsys.readouterr()
    assert main(["bundle", "--recheck", str(edited)]) == 1
    assert "artifacts/requirements/REQ2.json: record" in capsys.readouterr().err


def test_an_altered_second_solver_record_is_not_believed(ws: Path, tmp_path: Path) -> None:
    import shutil
    root = tmp_path / "ws"
    shutil.copytree(ws, root)
    index = root / "artifacts/crosscheck/index.json"
    index.write_text(index.read_text().replace('"two solvers"', '"one solver"', 1))
    assert main(["report", "-w", str(root)]) in (0, 1)
    r = _report(root)
    assert any(p.startswith("Second-solver record: second-solver record") for p in r["summary"]["problems"])
    assert r["meta"]["strict_ok"] is False


def test_refines_is_confirmed_by_the_second_solver(capsys: pytest.CaptureFixture[str]) -> None:
    from pathlib import Path as P
    rcl = str(P(__file__).resolve().parents[2] / "contracts/remote_inspection.rcl")
    assert main(["refines", f"{rcl}:RadiationSensor", f"{rcl}:RadiationSensor"]) == 0
    out = capsys.readouterr().out
    assert "second solver: assumption side: two solvers" in out and "guarantee side: two solvers" in out


def test_every_part_of_a_reset_joined_proof_is_decided() -> None:
    """A replacement check's two sides are joined by `(reset)`; both must be unsat for it to read ok."""
    both = ("(declare-fun x () Real)\n(assert (and (> x 1.0) (< x 0.0)))\n(check-sat)\n(reset)\n"
            "(declare-fun y () Real)\n(assert (and (> y 1.0) (< y 0.0)))\n(check-sat)\n")
    first_sat = ("(declare-fun x () Real)\n(assert (> x 1.0))\n(check-sat)\n(reset)\n"
                 "(declare-fun y () Real)\n(assert (and (> y 1.0) (< y 0.0)))\n(check-sat)\n")
    d = decide(both, every=True)
    assert d.answer == "unsat" and d.proof_checked
    assert decide(first_sat, every=True).answer == "sat"
    assert decide(first_sat).answer == "unsat"  # without `every`, only the last query counts (a side condition)


def test_a_row_for_another_text_of_the_query_is_not_believed(tmp_path: Path) -> None:
    """The second solver's row names the query's path and the sha256 of the text it decided; a query
    re-written at the same path since (a stage run without the crosscheck, `rclverify requirements`
    then `rclverify report`) was never seen by cvc5: it reads one solver, not the old agreement."""
    import hashlib

    from rclverify.stages.crosscheck.apply import load
    from rclverify.stages.crosscheck.stage import INDEX
    from rclverify.records.sealed import write_sealed
    rel = "artifacts/requirements/REQ1.smt2"
    (tmp_path / rel).parent.mkdir(parents=True)
    (tmp_path / rel).write_text(SAT_SCRIPT)
    row = {"kind": "requirement", "id": "REQ1", "smt2": rel, "verdict": "proved", "z3": "unsat",
           "sha256": hashlib.sha256(SAT_SCRIPT.encode()).hexdigest(), "agreement": "two solvers", "why": "both",
           "cvc5": {"answer": "unsat", "proof_checked": True, "version": "1", "reason": "", "proof": ""}}
    write_sealed(tmp_path / INDEX, {"solver": None, "counts": {}, "items": [row]})
    assert load(tmp_path).solvers("requirement", "REQ1", rel).agreement == "two solvers"
    (tmp_path / rel).write_text(SAT_SCRIPT.replace("1.0", "2.0"))
    s = load(tmp_path).solvers("requirement", "REQ1", rel)
    assert s.agreement == "one solver" and "another text" in s.why, s


def test_a_verdict_without_a_kept_query_says_so() -> None:
    """A proved temporal requirement keeps no single query: one solver, and not "run doit verify"
    (which would never give it a second one)."""
    from rclverify.stages.crosscheck.apply import SecondSolver
    rec = SecondSolver({}).requirement({"id": "T1", "verdict": "proved", "temporal": {"method": "k-induction"}})
    assert rec["solvers"]["agreement"] == "one solver" and "doit verify" not in rec["solvers"]["why"]


def test_a_shared_session_answers_and_proves_as_fresh_solvers_do(ws: Path) -> None:
    """One incremental solver for the quantifier-free scripts (the stage's
    speed-up) gives each script the answer and the proof text a fresh
    solver gives, whatever ran before it; quantified scripts are refused."""
    from rclverify.stages.crosscheck.cvc5_decide import RLIMIT, Session
    index = json.loads((ws / "artifacts/crosscheck/index.json").read_text())
    texts = [(ws / r["smt2"]).read_text() for r in index["items"]]
    # the realizability queries (quantified; the stage decides their witness queries: calculus/health/realizer.py)
    parts = [t.split("\n(reset)\n")[-1] for t in texts] + [
        p.read_text() for p in sorted((ws / "artifacts/health").glob("*.realizable.smt2"))]
    s = Session()
    taken = [p for p in parts if s.takes(p, RLIMIT, True, False)]
    refused = [p for p in parts if p not in taken]
    assert taken and refused and all("forall" in p or "exists" in p for p in refused)
    import re
    name = next(m.group(1) for p in taken for m in [re.search(r"\(declare-fun (\S+) \(\) Real\)", p)] if m)
    clash = f"(declare-fun {name} () Int)\n(assert (> {name} 2))\n(assert (< {name} 3))\n(check-sat)\n"
    for p in taken + [clash] + taken[::-1]:  # a name declared again with another sort: scoped away
        got, fresh = s.decide(p, "q", False), decide(p)
        assert got is not None and (got.answer, got.proof) == (fresh.answer, fresh.proof)
    assert decide(clash, session=s).answer == "unsat"
    for r, text in zip(index["items"], texts):  # as the stage calls it
        every = r["kind"] == "hoare" or (r["kind"] == "health" and r["z3"] == "unsat")
        got, fresh = decide(text, every=every, session=s), decide(text, every=every)
        assert (got.answer, got.proof) == (fresh.answer, fresh.proof) == (r["cvc5"]["answer"], got.proof)


def test_the_stage_split_over_two_processes_writes_what_the_serial_stage_writes(ws: Path, tmp_path: Path) -> None:
    """The stage decides the second half of many scripts in a forked process
    (issue 67): the same index (but the wall-clock durations) and the same
    proof files as deciding every script in this process, from an index that
    holds nothing to re-use.  Run in a fresh process: the stage forks only a
    process without other threads, and a test worker may hold threads an
    earlier module left (a Dask offload thread, asyncio's child watcher)."""
    import subprocess
    import sys
    script = ("import sys; sys.path.insert(0, sys.argv[1]); import test_second_solver as t; "
              "from pathlib import Path; print(t._split_and_serial(Path(sys.argv[2]), Path(sys.argv[3])))")
    done = subprocess.run([sys.executable, "-c", script, str(Path(__file__).parent), str(ws), str(tmp_path)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "same", done.stdout + done.stderr


def _split_and_serial(ws: Path, tmp: Path) -> str:
    """Run the stage on two copies of ``ws`` under ``tmp``, every script here, then half in a fork;
    ``"same"`` when both wrote the same index and proofs (AssertionError otherwise)."""
    import shutil
    import threading
    from rclverify.stages.crosscheck import stage
    assert threading.active_count() == 1  # a fresh process: the stage may fork
    nodes = sorted(p.stem for p in (ws / "artifacts/calculus").glob("*.json"))
    out = {}
    real = stage._decide_block
    stage._other_cpu_free = lambda: True  # type: ignore[assignment]  # whatever the machine's load
    for mode, split_min in (("serial", 10 ** 9), ("split", 1)):
        root = tmp / mode
        shutil.copytree(ws, root)
        shutil.rmtree(root / "artifacts/crosscheck")
        forked: list[int] = []
        stage._decide_block = lambda todo: forked.append(len(todo)) or real(todo)  # type: ignore[assignment]
        index = stage_crosscheck(root, nodes, split_min=split_min)
        # here: every script, or the first half (the child decides the rest in its copy of the process)
        assert forked == [len(index["items"]) if mode == "serial" else len(index["items"]) // 2], forked
        for r in index["items"]:
            r["cvc5"]["duration_s"] = 0
        proofs = {p.name: p.read_text() for p in (root / "artifacts/crosscheck/proofs").iterdir()}
        out[mode] = (index, proofs)
    assert out["split"] == out["serial"] and out["serial"][1]
    assert out["serial"][0]["counts"] == {"two solvers": len(out["serial"][0]["items"])}
    return "same"


def test_the_second_process_waits_for_a_free_cpu(monkeypatch: pytest.MonkeyPatch) -> None:
    """The stage forks its second process only when another CPU is free (issue 67): two CPUs, this
    process's own idle while it sleeps and half of another; one CPU or a busier machine decide in this
    process.  Where the CPU counters cannot be read, the load average of the last minute decides."""
    from rclverify.stages.crosscheck import stage
    for cpus, idle, free in (({0, 1}, 2.0, True), ({0, 1}, 1.5, True), ({0, 1}, 1.4, False), ({0, 1}, 0.0, False),
                             ({0}, 1.0, False), ({0, 1, 2, 3}, 1.6, True)):
        monkeypatch.setattr(stage, "_cpus", lambda c=cpus: c)
        monkeypatch.setattr(stage.cpus_now, "idle_cpus", lambda x=idle: x)
        monkeypatch.setattr(stage.os, "getloadavg", lambda: (0.0, 0.0, 0.0))  # not read: the counters decide
        assert stage._other_cpu_free() is free, (cpus, idle)
    monkeypatch.setattr(stage.cpus_now, "idle_cpus", lambda: None)
    for cpus, load, free in (({0, 1}, 0.9, True), ({0, 1}, 1.5, True), ({0, 1}, 1.6, False), ({0, 1}, 4.0, False),
                             ({0}, 0.0, False), ({0, 1, 2, 3}, 3.0, True)):
        monkeypatch.setattr(stage, "_cpus", lambda c=cpus: c)
        monkeypatch.setattr(stage.os, "getloadavg", lambda x=load: (x, x, x))
        assert stage._other_cpu_free() is free, (cpus, load)
