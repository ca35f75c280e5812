"""Tests of the hoare backend: language, weakest preconditions, triples from
the Radiation Sensor's guarantee, Z3 checking, and the backend end to end."""
from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
import z3

from rclverify.backends.base import NodeTarget
from rclverify.backends.hoare import HoareBackend
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.check import check_program
from rclverify.backends.hoare.outline import render_outline, outline_text, z3_text
from rclverify.backends.hoare.solve import check_all
from rclverify.backends.hoare.program_model import ProgramModel
from rclverify.backends.hoare.wp import main_vc, wp
from rclverify.records.records import Obligation
from rclverify.semantics.encode import Encoder
from rclverify.model.plan.errors import PlanError
from rclverify.lang.errors import RclError
from rclverify.lang.typecheck import load

REPO = Path(__file__).resolve().parents[2]
RCL = "contracts/remote_inspection.rcl"
PLAN = "contracts/plan.yaml"
PROGRAM = "backends/hoare/radiation_sensor.imp"
APPENDIX_B = "backends/hoare/radiation_sensor_appendix_b.imp"
BINDING = {"in.r": "radiation_at(i)", "out.radiationStatus": "output"}


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def checked() -> Any:
    return load([REPO / RCL])


@pytest.fixture()
def workspace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the case-study workspace (contracts, plan, Hoare programs)."""
    for rel in (RCL, PLAN, PROGRAM, APPENDIX_B):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(REPO / rel, tmp_path / rel)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def target(root: Path, config: dict[str, Any]) -> NodeTarget:
    checked = load([RCL])  # relative to the workspace (cwd), as the tool loads it
    return NodeTarget(root=root, checked=checked, node=checked.nodes["RadiationSensor"], config=config,
                      contract_files=(RCL,), plan_file=PLAN,
                      artifacts=root / "artifacts" / "hoare" / "RadiationSensor")


def entry(program: str = PROGRAM, **extra: Any) -> dict[str, Any]:
    return {"backend": "hoare", "program": program, "binding": dict(BINDING), **extra}


def run_all(t: NodeTarget) -> dict[str, tuple[Obligation, Any]]:
    b = HoareBackend()
    return {o.instance: (o, b.run(o, t)) for o in b.export(t)}


def model_of(src: str, checked: Any) -> tuple[lang.Program, ProgramModel, Encoder]:
    prog = lang.parse_program(src, "t.imp")
    enc = Encoder(checked.env)
    return prog, ProgramModel(prog, check_program(prog, checked.env), enc), enc


def equivalent(a: z3.BoolRef, b: z3.BoolRef) -> bool:
    s = z3.Solver()
    s.add(a != b)
    return s.check() == z3.unsat


# ---------------------------------------------------------------------------
# the language
# ---------------------------------------------------------------------------

def test_case_study_program_parses_with_the_papers_spelling() -> None:
    prog = lang.parse_program_file(REPO / PROGRAM, PROGRAM)
    assert [d.name for d in prog.vars] == ["i", "input", "output"]
    assert prog.externs[0].name == "radiation_at"
    first, branch = prog.body
    assert first == lang.Assign("input", lang.Call("radiation_at", (lang.Name("i"),)))
    assert isinstance(branch, lang.If) and branch.cond == lang.Binary("<", lang.Name("input"), lang.Num("120"))
    inner = branch.else_[0]
    assert isinstance(inner, lang.If) and inner.else_ == (lang.Assign("output", lang.Name("red")),)
    assert branch.loc.file == PROGRAM and branch.loc.line > first.loc.line > 1


def test_print_then_parse_round_trips() -> None:
    src = """
    var n, k : NATURAL; var s : INTEGER; var x : REAL; var ok : BOOL;
    extern f : NATURAL x REAL --> REAL;
    s := 0; k := n
    while k > 0 and not ok invariant s == old(n) - k invariant k >= 0 do
      s := s + 1
      k := k - 1
    end
    if x < 1.5 then skip elif (x - (1 - x)) * 2 > f(n, x) or ok -> s = 3 then x := -x / 2 else ok := TRUE end
    IF (ok) THEN x := 1 ELSE IF (x > 2) THEN x := 2
    """
    prog = lang.parse_program(src)
    text = lang.to_text(prog)
    again = lang.parse_program(text)
    assert again == prog
    assert lang.to_text(again) == text
    assert "while k > 0 and not ok invariant s == old(n) - k and k >= 0 do" in text
    assert "elif (x - (1 - x)) * 2 > f(n, x) or ok -> s == 3 then" in text
    # the paper's IF/THEN/ELSE without 'end' takes one statement per branch
    last = prog.body[-1]
    assert isinstance(last, lang.If) and len(last.else_) == 1 and isinstance(last.else_[0], lang.If)


def test_expression_printer_keeps_needed_parentheses_only() -> None:
    for text in ["(a or b) and c", "a - (b - c)", "a -> b -> c", "(a -> b) -> c", "not (x < 1)", "-(x + 1) * 2"]:
        e = lang.parse_expression(text)
        assert lang.parse_expression(lang.expr_text(e)) == e
    assert lang.expr_text(lang.parse_expression("((a and b)) or (c)")) == "a and b or c"


def test_parse_error_is_located_in_the_program_file() -> None:
    with pytest.raises(RclError) as exc:
        lang.parse_program("var x : INTEGER;\nwhile x > 0 do\n  x := x - 1\nend\n", "loop.imp")
    d = exc.value.diagnostics[0]
    assert (d.loc.file, d.loc.line, d.loc.col) == ("loop.imp", 2, 13)
    assert "'invariant'" in d.message
    with pytest.raises(RclError) as exc:
        lang.parse_program("var x : REAL;\nx := 1 +* 2\n", "bad.imp")
    assert str(exc.value.diagnostics[0]).startswith("bad.imp:2:9: error: unexpected '*'")


def test_checker_reports_located_name_and_type_errors(checked: Any) -> None:
    src = "var o : RadStatus;\nvar x : REAL;\nextern f : NATURAL --> REAL;\nx := f(x)\ny := 1\nx := gren\n"
    with pytest.raises(RclError) as exc:
        check_program(lang.parse_program(src, "bad.imp"), checked.env)
    msgs = [str(d) for d in exc.value.diagnostics]
    assert msgs[0].startswith("bad.imp:1:") and "unknown type 'RadStatus'" in msgs[0] and "RadStat" in msgs[0]
    assert any(m.startswith("bad.imp:4:8:") and "argument of f must be NATURAL, found REAL" in m for m in msgs)
    assert any(m.startswith("bad.imp:5:") and "undeclared variable 'y'" in m for m in msgs)
    assert any(m.startswith("bad.imp:6:6:") and "'gren'" in m and "green" in m for m in msgs)


# ---------------------------------------------------------------------------
# weakest preconditions
# ---------------------------------------------------------------------------

def test_wp_of_assignment_substitutes(checked: Any) -> None:
    prog, m, _ = model_of("var x, y : INTEGER;\nx := x + y\n", checked)
    x, y = m.consts["x"], m.consts["y"]
    res = wp(prog.body, x > 3, m)
    assert equivalent(res.pre, x + y > 3)
    assert not equivalent(res.pre, x > 3)
    assert res.vcs == ()


def test_wp_of_assignment_to_natural_checks_the_range(checked: Any) -> None:
    prog, m, _ = model_of("var n : NATURAL;\nn := n - 1\n", checked)
    n = m.consts["n"]
    res = wp(prog.body, z3.BoolVal(True), m)
    assert equivalent(res.pre, n - 1 >= 0)


def test_wp_of_if_is_the_conditional_rule(checked: Any) -> None:
    prog, m, enc = model_of("var x : REAL; var o : RadStat;\nif x < 120 then o := green else o := red end\n",
                            checked)
    x, o = m.consts["x"], m.consts["o"]
    green, red = enc.enum_value("green"), enc.enum_value("red")
    res = wp(prog.body, o == green, m)
    assert equivalent(res.pre, x < 120)
    assert o.sort() == enc.sort(checked.env.types["RadStat"])  # the contract's sort, not a copy
    res2 = wp(prog.body, o == red, m)
    assert equivalent(res2.pre, x >= 120)


def test_wp_of_while_is_the_invariant_with_two_side_conditions(checked: Any) -> None:
    prog, m, _ = model_of("var k : NATURAL; var s : INTEGER;\n"
                          "while k > 0 invariant s + k == 10 do\n  s := s + 1\n  k := k - 1\nend\n", checked)
    k, s = m.consts["k"], m.consts["s"]
    res = wp(prog.body, s == 10, m)
    inv = s + k == 10
    assert equivalent(res.pre, inv)
    assert [vc.id for vc in res.vcs] == ["loop@2.preserve", "loop@2.exit"]
    preserve, exit_ = res.vcs
    assert equivalent(z3.And(*preserve.hyps), z3.And(inv, k > 0))
    assert equivalent(preserve.goal, z3.And(k - 1 >= 0, (s + 1) + (k - 1) == 10))
    assert equivalent(z3.And(*exit_.hyps), z3.And(inv, z3.Not(k > 0)))
    assert equivalent(exit_.goal, s == 10)
    result = check_all([main_vc(inv, res, m, prog.body[0].loc), *res.vcs], [], m, 10_000)
    assert result.status == "discharged"


def _loop_triple(checked: Any, inv: str, start: str = "0", pre: Any = None) -> Any:
    """``s := start; while k > 0 invariant inv do s := s + 1; k := k - 1 end`` against ``s == old(k)``."""
    prog, m, _ = model_of("var k : NATURAL; var s : INTEGER;\n"
                          f"s := {start}\nwhile k > 0 invariant {inv} do\n  s := s + 1\n  k := k - 1\nend\n", checked)
    post = m.consts["s"] == m.olds["k"]
    pre = z3.BoolVal(True) if pre is None else pre(m)
    res = wp(prog.body, post, m)
    return check_all([main_vc(pre, res, m, prog.body[0].loc), *res.vcs], [], m, 10_000, triple=(pre, post))


def test_a_loop_invariant_too_weak_leaves_a_true_triple_unproved_not_failed(checked: Any) -> None:
    assert _loop_triple(checked, "s + k == old(k)").status == "discharged"  # the control: the triple is true
    weak = _loop_triple(checked, "s >= 0")  # too weak to give s == old(k) on exit
    assert weak.status == "inconclusive" and weak.counterexample is None
    [why] = weak.notes
    assert why.startswith("Z3 refutes loop@3.exit") and "which no run need reach" in why
    assert "the run from the initial values it gives meets the postcondition" in why
    unkept = _loop_triple(checked, "s + k == old(k) and s <= 0")  # not preserved
    assert unkept.status == "inconclusive" and unkept.notes[0].startswith("Z3 refutes loop@3.preserve")
    # an invariant false on entry (k <= 5 for 5 < k <= 10): the main VC's model is a run that meets the post
    entry = _loop_triple(checked, "s + k == old(k) and k <= 5", pre=lambda m: m.consts["k"] <= 10)
    assert entry.status == "inconclusive" and entry.notes[0].startswith("Z3 refutes main"), entry.notes


def test_a_wrong_loop_fails_with_the_run_that_breaks_it(checked: Any) -> None:
    # s starts at 1: the invariant s + k == old(k) + 1 holds and is kept; on exit s == old(k) + 1, not old(k)
    out = _loop_triple(checked, "s + k == old(k) + 1", start="1")
    assert out.status == "failed" and out.failed is not None and out.failed.vc.id == "loop@3.exit"
    cex = out.counterexample or {}
    assert cex["s (final)"] == cex["k"] + 1 and cex["k (final)"] == 0, cex  # a run from k, replayed to its end
    # the weak invariant on the same wrong program: its refuted exit VC still yields the breaking run
    assert _loop_triple(checked, "s >= 0", start="1").status == "failed"


def test_outline_annotates_each_statement_like_the_papers_figure(checked: Any) -> None:
    prog = lang.parse_program_file(REPO / PROGRAM, PROGRAM)
    m = ProgramModel(prog, check_program(prog, checked.env), Encoder(checked.env))
    enc = m.sorts
    post = m.consts["output"] == enc.enum_value("green")
    res = wp(prog.body, post, m)
    text = outline_text(render_outline(res.outline))
    lines = text.splitlines()
    assert lines[0].startswith("{ (radiation_at(i) < 120 -> green == green) and ")
    assert lines[1] == "input := radiation_at(i)"
    assert lines[2].startswith("{ (input < 120 -> green == green) and ") and "conditional rule" in lines[2]
    assert lines[3] == "if input < 120 then"
    assert lines[4].startswith("  { green == green }") and "assignment axiom" in lines[4]
    assert lines[-1].startswith("{ output == green }") and "postcondition" in lines[-1]
    assert z3_text(res.pre).startswith("(radiation_at(i) < 120 -> green == green)")


# ---------------------------------------------------------------------------
# the case study through the backend
# ---------------------------------------------------------------------------

def test_case_study_green_orange_red_are_discharged(workspace: Path) -> None:
    results = run_all(target(workspace, entry()))
    assert sorted(results) == [f"radiation_sensor.c{k}" for k in (1, 2, 3, 4)]
    for inst, colour, premise in (("c2", "green", "in.r < 120"), ("c3", "orange", "120 <= in.r and in.r < 250"),
                                  ("c4", "red", "250 <= in.r")):
        o, ev = results[f"radiation_sensor.{inst}"]
        assert o.id == f"RadiationSensor.g1.hoare.radiation_sensor.{inst}"
        assert premise in o.statement and f"{{out.radiationStatus == {colour}}}" in o.statement
        assert "in.r = radiation_at(i)" in o.statement and "i = program variable i" in o.statement
        assert ev.status == "discharged", ev.explanation
        assert ev.tool == "z3" and ev.tool_version == z3.get_version_string()
        assert ev.details["vcs"] == {"main": "valid"}
        assert "input := radiation_at(i)" in ev.details["outline"]
        assert f"{{ output == {colour} }}" in ev.details["outline"]
        assert ev.counterexample is None


def test_inspected_conjunct_is_pending_never_discharged(workspace: Path) -> None:
    o, ev = run_all(target(workspace, entry()))["radiation_sensor.c1"]
    assert "out.inspected(i) == TRUE" in o.statement
    assert o.data["pending"] == ("the program does not model out.inspected; bind it in the plan or cover it "
                                 "with another backend")
    assert ev.status == "pending" and ev.explanation == o.data["pending"]
    assert ev.details["uncovered"] == ["out.inspected"]


def test_appendix_b_program_is_refuted_against_the_contract(workspace: Path) -> None:
    results = run_all(target(workspace, entry(APPENDIX_B)))
    _, green = results["radiation_sensor_appendix_b.c2"]
    assert green.status == "failed"
    cex = green.counterexample
    assert cex is not None
    r = cex["radiation_at(i)"]
    # 10/20 and 120/250 disagree on green exactly for levels in [10, 120)
    assert 10 <= r < 120 and cex["in.r"] == r and isinstance(cex["i"], int) and cex["i"] >= 0
    assert cex["output (final)"] in ("orange", "red") and cex["out.radiationStatus"] == cex["output (final)"]
    assert cex["output (final)"] == ("orange" if r < 20 else "red")
    assert green.details["failed_vc"] == "main"
    _, orange = results["radiation_sensor_appendix_b.c3"]
    assert orange.status == "failed"
    assert orange.counterexample is not None and 120 <= orange.counterexample["radiation_at(i)"] < 250
    assert orange.counterexample["output (final)"] == "red"
    # above both upper thresholds the two programs agree
    assert results["radiation_sensor_appendix_b.c4"][1].status == "discharged"


def test_a_changed_threshold_is_refuted(workspace: Path) -> None:
    path = workspace / PROGRAM
    path.write_text(path.read_text().replace("input < 250", "input < 200"))
    results = run_all(target(workspace, entry()))
    assert results["radiation_sensor.c2"][1].status == "discharged"
    assert results["radiation_sensor.c4"][1].status == "discharged"  # >= 250 is still red
    ev = results["radiation_sensor.c3"][1]
    assert ev.status == "failed"
    assert 200 <= ev.counterexample["radiation_at(i)"] < 250
    assert ev.counterexample["output (final)"] == "red"


def test_export_renders_deterministic_artifacts_and_records_inputs(workspace: Path) -> None:
    t = target(workspace, entry())
    first = {o.id: o for o in HoareBackend().export(t)}
    texts = {i: (workspace / o.artifact).read_text() for i, o in first.items()}
    second = {o.id: o for o in HoareBackend().export(t)}
    assert {i: o.to_json() for i, o in first.items()} == {i: o.to_json() for i, o in second.items()}
    assert texts == {i: (workspace / o.artifact).read_text() for i, o in second.items()}
    o = first["RadiationSensor.g1.hoare.radiation_sensor.c2"]
    assert o.artifact == "artifacts/hoare/RadiationSensor/g1.radiation_sensor.c2.txt"
    assert set(o.inputs) == {PROGRAM, RCL, PLAN}
    assert o.kind == "proof" and o.backend == "hoare" and o.source.file == RCL and o.source.line > 1
    text = texts[o.id]
    header = text.splitlines()[0]
    assert header.startswith("// ") and f"{RCL}:{o.source.line}" in header and "generated by rclverify" in header
    assert str(workspace) not in text
    assert "Proof outline" in text and "output := green" in text
    json.dumps(o.to_json())  # serialisable


def test_run_writes_the_smt_queries_which_z3_reproduces(workspace: Path) -> None:
    t = target(workspace, entry(APPENDIX_B))
    b = HoareBackend()
    o = next(o for o in b.export(t) if o.instance.endswith("c2"))
    ev = b.run(o, t)
    smt = next(a for a in ev.artifacts if a.endswith(".smt2"))
    text = (workspace / smt).read_text()
    assert text.startswith("; ") and "generated by rclverify" in text.splitlines()[0]
    body = "\n".join(ln for ln in text.splitlines() if not ln.startswith(";"))
    s = z3.Solver()
    s.from_string(body.replace("(push 1)", "").replace("(pop 1)", "").replace("(check-sat)", ""))
    assert s.check() == z3.sat  # the refuted VC: its negation is satisfiable


def test_plan_errors_are_located_in_the_plan(workspace: Path) -> None:
    with pytest.raises(PlanError) as exc:
        HoareBackend().export(target(workspace, {"backend": "hoare", "program": "backends/hoare/missing.imp"}))
    assert "does not exist" in str(exc.value) and exc.value.diagnostics[0].loc.file == PLAN
    bad = entry()
    bad["binding"] = {"in.radiation": "radiation_at(i)"}
    with pytest.raises(PlanError) as exc:
        HoareBackend().export(target(workspace, bad))
    assert "in.radiation is not an input of RadiationSensor" in str(exc.value)
    bad["binding"] = {"in.r": "radiation_at(j)"}
    with pytest.raises(RclError) as exc:
        HoareBackend().export(target(workspace, bad))
    assert "undeclared name 'j'" in str(exc.value)
    bad["binding"] = {"out.radiationStatus": "input"}
    with pytest.raises(PlanError) as exc:
        HoareBackend().export(target(workspace, bad))
    assert "out.radiationStatus is RadStat but variable 'input' is REAL" in str(exc.value)


def test_unbound_output_makes_every_status_conjunct_pending(workspace: Path) -> None:
    cfg = entry()
    cfg["binding"] = {"in.r": "radiation_at(i)"}
    results = run_all(target(workspace, cfg))
    assert {ev.status for _, ev in results.values()} == {"pending"}
    assert "out.radiationStatus" in results["radiation_sensor.c2"][1].explanation


def test_program_syntax_error_stops_export_with_a_location(workspace: Path) -> None:
    path = workspace / PROGRAM
    path.write_text(path.read_text().replace("output := orange", "output = orange"))
    with pytest.raises(RclError) as exc:
        HoareBackend().export(target(workspace, entry()))
    d = exc.value.diagnostics[0]
    assert d.loc.file == PROGRAM and d.loc.line == 20


def test_unknown_answer_is_inconclusive_never_discharged(checked: Any) -> None:
    prog, m, _ = model_of("var x, y, z : INTEGER;\nskip\n", checked)
    x, y, z = m.consts["x"], m.consts["y"], m.consts["z"]
    res = wp(prog.body, x * x * x + y * y * y != z * z * z, m)  # Fermat, n = 3: beyond Z3's nonlinear arithmetic
    out = check_all([main_vc(z3.And(x > 0, y > 0, z > 0), res, m, prog.body[0].loc)], [], m, 300)
    assert out.status == "inconclusive" and out.counterexample is None
    assert out.results[0].status == "unknown" and out.results[0].reason


CONVERSE = """
context { RadStat : {red, orange, green} ; }
node Sensor {
  inputs( r : REAL )
  outputs( radiationStatus : RadStat )
  assume( 0 <= in.r )
  guarantee( forall(i in NATURAL | out.radiationStatus == red -> in.r >= 250) )
  guarantee( forall(k in NATURAL | in.r < k and k <= 250 -> out.radiationStatus != red) )
}
"""


@pytest.mark.parametrize("program, refuted", [(PROGRAM, False), (APPENDIX_B, True)])
def test_premise_over_an_output_moves_to_the_postcondition(workspace: Path, program: str, refuted: bool) -> None:
    (workspace / "contracts" / "sensor.rcl").write_text(CONVERSE)
    checked = load(["contracts/sensor.rcl"])
    t = NodeTarget(root=workspace, checked=checked, node=checked.nodes["Sensor"], config=entry(program),
                   contract_files=("contracts/sensor.rcl",), plan_file=PLAN, artifacts=workspace / "out")
    b = HoareBackend()
    obs = {o.id.split(".g")[1][:1]: o for o in b.export(t)}
    first = obs["1"]
    # the premise reads the output, so it is checked after the program; in.r is then the initial level
    assert "{0 <= in.r} " in first.statement and "{out.radiationStatus == red -> in.r >= 250}" in first.statement
    ev = b.run(first, t)
    assert ev.details["triple"]["post"] == "output == red -> radiation_at(old(i)) >= 250"
    if refuted:
        assert ev.status == "failed" and 20 <= ev.counterexample["radiation_at(i)"] < 250
        assert ev.counterexample["output (final)"] == "red"
    else:
        assert ev.status == "discharged", ev.explanation
    # a bound variable that is not a program variable is a fixed, arbitrary value
    second = b.run(obs["2"], t)
    assert second.status == ("failed" if refuted else "discharged")
    if refuted:
        cex = second.counterexample
        assert 20 <= cex["radiation_at(i)"] < cex["k"] <= 250 and cex["output (final)"] == "red"


def test_bad_binding_is_located_at_its_key_in_the_plan(tmp_path: Path) -> None:
    import shutil
    from rclverify.app.pipeline import Workspace
    from rclverify.model.plan.errors import PlanError
    for item in ("contracts", "backends"):
        shutil.copytree(REPO / item, tmp_path / item)
    plan = tmp_path / "contracts" / "plan.yaml"
    text = plan.read_text().replace("in.r: radiation_at(i)", "in.rr: radiation_at(i)", 1)
    plan.write_text(text)
    ws = Workspace(tmp_path)
    index = next(e.index for e in ws.plan.evidence["RadiationSensor"] if e.backend == "hoare")
    with pytest.raises(PlanError) as exc:
        HoareBackend().export(ws.target("RadiationSensor", index))
    d = exc.value.diagnostics[0]
    line = text.splitlines()[d.loc.line - 1]
    assert d.loc.file == "contracts/plan.yaml" and line[d.loc.col - 1:].startswith("in.rr:")
    assert "in.rr is not an input of RadiationSensor" in d.message


def test_the_export_writes_the_same_in_a_used_z3_context_and_makes_none(tmp_path: Path) -> None:
    """The node task's export needs no fresh Z3 context of its own (app/pipeline.py,
    ``stage_export``): exported into a context that other work filled (terms, a
    solver's model) it writes the same obligation records and artifacts, and a
    plan whose entries are all Hoare ones leaves the context it found in place."""
    from rclverify.app.pipeline import Workspace, stage_check, stage_export
    from rclverify.semantics.world import fresh
    ws_dir = tmp_path / "stop"
    shutil.copytree(REPO / "tests" / "data" / "requirements" / "stop", ws_dir)
    ws = Workspace(ws_dir)
    stage_check(ws)
    nodes = ["ObstacleDetector", "SpeedController", "MotorDriver"]

    def written() -> dict[str, str]:
        return {p.relative_to(ws_dir).as_posix(): p.read_text() for d in ("obligations", "hoare")
                for p in sorted((ws_dir / "artifacts" / d).rglob("*")) if p.is_file()}
    fresh()
    clean = {n: stage_export(ws, n) for n in nodes}
    files = written()
    shutil.rmtree(ws_dir / "artifacts" / "hoare")
    fresh()
    x, y = z3.Reals("x y")  # other work first: terms, a query and its model in the same context
    s = z3.Solver()
    s.add(x + y > 3, x < y, y * y < 17)
    assert s.check() == z3.sat and s.model() is not None
    ctx = z3.main_ctx()
    used = {n: stage_export(ws, n) for n in reversed(nodes)}
    assert z3.main_ctx() is ctx  # no context of its own
    assert used == clean and written() == files
