"""Rules S1 and D1-D3 (docs/decisions.md, "Services, actions and
deadlines"): service links in the system model, deadlines adding along a
path, the end-to-end deadline decided by Z3 with the chain named."""
from __future__ import annotations

import json
import shutil
from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.calculus.deadlines import INCONCLUSIVE, PROVED, REFUTED, chains, decide
from rclverify.cli.commands import main
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "safety_stop"

CHAIN = """\
node A {
  inputs( a : REAL )
  outputs( b : REAL )
  guarantee( out.b == in.a ) triggered by in.a within 100 ms
}
node B {
  inputs( b : REAL )
  outputs( c : REAL )
  guarantee( out.c == in.b + 1 ) triggered by in.b within 150 ms
  guarantee( out.c >= in.b ) triggered by in.b within 0.4 s
}
node C {
  inputs( c : REAL )
  outputs( d : REAL )
  guarantee( out.d == in.c ) triggered by in.c within 300 ms
  guarantee( out.d == out.d )
}
"""


def system(text: str):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "s.rcl")])
    return checked, build(checked)


def test_deadlines_add_along_the_path_and_z3_decides() -> None:
    checked, model = system(CHAIN)
    found, why = chains(checked, model, ["A", "B", "C"])
    assert why == "" and len(found) == 2  # B has two timed guarantees: two chains
    late = decide(checked, model, "R", ["A", "B", "C"], Fraction(1, 2))
    assert late.status == REFUTED
    assert late.total == Fraction(55, 100)  # the tightest chain: 100 + 150 + 300 ms
    assert [(h.node, h.index) for h in late.chain] == [("A", 1), ("B", 1), ("C", 1)]
    assert "A guarantee 1 (in.a -> out.b within 100 ms) -> B guarantee 1" in late.reason
    assert "sums to 550 ms > 500 ms" in late.reason
    # Z3's model is a late run: every hop within its own deadline, the path past 500 ms
    t = dict(late.stamps)
    assert list(t) == ["A.in.a", "B.in.b", "C.in.c", "C.out.d"]
    assert t["A.in.a"] == 0 and t["C.out.d"] > Fraction(1, 2)
    assert t["B.in.b"] - t["A.in.a"] <= Fraction(1, 10) and t["C.in.c"] - t["B.in.b"] <= Fraction(15, 100)
    assert "(declare-fun t3 () Real)" in late.smt2
    ok = decide(checked, model, "R", ["A", "B", "C"], Fraction(55, 100))
    assert ok.status == PROVED and ok.stamps == () and "550 ms <= 550 ms" in ok.reason


def test_a_broken_path_is_inconclusive_naming_the_hop() -> None:
    checked, model = system(CHAIN)
    r = decide(checked, model, "R", ["A", "C"], Fraction(1))
    assert r.status == INCONCLUSIVE
    assert r.reason == "no timed guarantee of C is triggered by an output of A's timed guarantees (out.b)"
    r = decide(checked, model, "R", ["C", "A"], Fraction(1))
    assert r.status == INCONCLUSIVE and "no timed guarantee of A" in r.reason


def test_a_service_links_client_and_server() -> None:
    checked, model = system((EXAMPLE / "contracts" / "safety_stop.rcl").read_text())
    via = {(lk.from_node, lk.from_var, lk.to_node, lk.to_var): lk.via for lk in model.links}
    assert via[("Base", "stopped", "Teleop", "stop_ack")] == "service"  # the response goes back
    assert via[("Teleop", "stop_req", "Base", "stop_req")] == "name"  # a name match wins, as before
    assert ("Teleop", "stop_ack") not in [(n, v) for n, v, _ in model.env_inputs]
    assert ("Teleop", "button") in [(n, v) for n, v, _ in model.env_inputs]


def test_service_side_conditions_are_located() -> None:
    text = (EXAMPLE / "contracts" / "safety_stop.rcl").read_text()
    twice = text + """
node Base2 {
  inputs( stop_req : BOOL )
  outputs( stopped2 : BOOL )
  services( std_srvs/Trigger estop serves(in.stop_req, out.stopped2) )
  guarantee( out.stopped2 )
}
"""
    with pytest.raises(RclError) as exc:
        system(twice)
    msgs = [str(d) for d in exc.value.diagnostics]
    assert any(m.startswith("s.rcl:46:13: error: service 'estop' has type std_srvs/Trigger here but "
                            "std_srvs/SetBool in node Teleop") for m in msgs), msgs
    assert any(m.startswith("s.rcl:46:13: error: service 'estop' already has a server, node Base") for m in msgs)


def _copy(tmp_path: Path) -> Path:
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", "*.pyc", "__pycache__"))
    return ws


def test_cli_proves_the_example_and_refutes_a_tighter_requirement(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path)
    assert main(["deadlines", "-w", str(ws)]) == 0
    out = capsys.readouterr().out
    assert "STOP: end-to-end deadline 300 ms along Teleop -> Base: proved" in out
    assert "MOVE-FEEDBACK: end-to-end deadline 2 s along Mover: proved" in out
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text(plan.read_text().replace("within: 300 ms", "within: 200 ms"))
    assert main(["deadlines", "-w", str(ws)]) == 1
    out = capsys.readouterr().out
    assert "STOP: end-to-end deadline 200 ms along Teleop -> Base: refuted" in out
    assert ("the chain Teleop guarantee 1 (in.button -> out.stop_req within 50 ms) -> Base guarantee 1 "
            "(in.stop_req -> out.stopped within 200 ms) sums to 250 ms > 200 ms") in out
    rec = json.loads((ws / "artifacts" / "deadlines" / "index.json").read_text())["results"]
    assert [r["status"] for r in rec] == ["refuted", "proved"]
    assert rec[0]["smt2"] == "artifacts/deadlines/STOP.smt2" and (ws / rec[0]["smt2"]).is_file()
    assert [h["node"] for h in rec[0]["chain"]] == ["Teleop", "Base"]


def test_plan_deadline_without_unit_or_unknown_node_is_located(tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    ws = _copy(tmp_path)
    plan = ws / "contracts" / "plan.yaml"
    text = plan.read_text()
    plan.write_text(text.replace("within: 300 ms", "within: 300"))
    assert main(["deadlines", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert "contracts/plan.yaml:12:46: error: deadline 'within: 300' must be a positive number and a unit" in err
    assert "Traceback" not in err
    plan.write_text(text.replace("path: [Teleop, Base]", "path: [Teleop, Bse]"))
    assert main(["deadlines", "-w", str(ws)]) == 1
    assert "contracts/plan.yaml:12:15: error: no node named 'Bse' in the contracts" in capsys.readouterr().err


def test_backends_say_they_check_the_untimed_part_only(tmp_path: Path) -> None:
    ws = _copy(tmp_path)
    assert main(["verify", "-w", str(ws)]) == 0
    ev = {p.stem: json.loads(p.read_text()) for p in (ws / "artifacts" / "evidence").glob("*.json")}
    hoare = ev["Base.g1.hoare.base.c1"]
    assert hoare["status"] == "discharged"
    assert hoare["explanation"].startswith("untimed part only: hoare checks guarantee 1's formula, not its "
                                           "timing 'triggered by in.stop_req within 200 ms'")
    assert hoare["details"]["timing"]["checked"] is False
    prop = ev["Mover.g1.property_tests.e0"]
    assert prop["details"]["timing"]["clause"] == "triggered by in.target within 2 s"
    untimed = ev["Mover.g2.property_tests.e0"]  # guarantee 2 has no timing: nothing added
    assert "timing" not in untimed["details"] and "untimed" not in untimed["explanation"]


@pytest.mark.parametrize("backend", ["dafny", "ajpf", "hoare", "property_tests", "experiment", "review"])
def test_every_untimed_backend_says_so_and_the_monitors_do_not(backend: str) -> None:
    from rclverify.backends.timing_scope import scope
    checked, _ = system((EXAMPLE / "contracts" / "safety_stop.rcl").read_text())
    base = checked.nodes["Base"]
    text, details = scope(backend, base, 1, "ran", {"k": 1})
    assert text.startswith(f"untimed part only: {backend} checks guarantee 1's formula") and text.endswith(". ran")
    assert details["k"] == 1 and details["timing"]["clause"] == "triggered by in.stop_req within 200 ms"
    assert scope("monitors", base, 1, "ran", {}) == ("ran", {})
