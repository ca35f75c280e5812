"""Counterexamples a person can read (issue 48): values within the shown
nodes' assumptions (or a sentence saying why not), integers and short
decimals where a witness with them exists, re-checked; only the nodes that
matter shown (a side condition's linked nodes, a temporal trace's named and
changing variables); the warehouse example read the same way."""
from __future__ import annotations

import shutil
from fractions import Fraction
from pathlib import Path

import pytest
import z3

from rclverify.semantics import world
from rclverify.semantics.nicemodel import nicer_model, short
from rclverify.records.side_condition_rows import SideConditionRow
from rclverify.report.cex_cone import side_condition_view, trace_view
from tests.records._typed_rows import complete
from rclverify.calculus.requirements.check import check_requirement as _check_requirement
from rclverify.stages.workspace import Workspace

REPO = Path(__file__).resolve().parents[2]

RCL = """
node Source {
  inputs( raw : REAL )
  outputs( dest : REAL, gain : REAL )
  assume( 0 <= in.raw and in.raw <= 1000 )
  guarantee( out.dest == in.raw )
  guarantee( 7 * out.gain > 100 and out.gain < 20 )
}
node Planner {
  inputs( dest : REAL, gain : REAL )
  outputs( goal : REAL, speed : REAL )
  assume( in.dest <= 500 and in.gain <= 19 )
  guarantee( out.goal == in.dest / 50 )
  guarantee( out.speed == in.gain )
}
"""
PLAN = """contracts: [contracts/robot.rcl]
requirements:
  - id: NEAR
    text: the goal is within 10 (only an input outside Planner's assumption refutes it)
    formal: "Planner.out.goal <= 10"
  - id: SLOW
    text: the planned speed stays at most 14
    formal: "Planner.out.speed <= 14 or Planner.out.goal > 9"
  - id: HIGH
    text: a goal past 9 (refuted within the assumptions, e.g. at 450)
    formal: "Planner.out.goal < 9"
"""


class _Sym:
    def __init__(self, decl: z3.ExprRef, display: str) -> None:
        self.decl, self.display, self.z3name = decl, display, str(decl)


class _Enc:
    """The part of the encoder nicer_model reads: the symbols and their axioms."""

    def __init__(self, *syms: tuple[z3.ExprRef, str]) -> None:
        self.symbols = {str(d): _Sym(d, n) for d, n in syms}

    def axioms(self) -> list[z3.BoolRef]:
        return []


def _holds(formulas: list[z3.BoolRef], values: dict[z3.ExprRef, str]) -> bool:
    """Do ``formulas`` hold with each constant at its text value (substituted, simplified)?"""
    subs = [(c, z3.RealVal(Fraction(v)) if z3.is_real(c) else z3.IntVal(int(v))) for c, v in values.items()]
    return all(z3.is_true(z3.simplify(z3.substitute(f, *subs))) for f in formulas)


def test_a_rational_becomes_an_integer_and_the_model_still_satisfies_the_query() -> None:
    y, x = z3.Real("y"), z3.Real("x")
    enc = _Enc((y, "A.out.y"), (x, "A.in.x"))
    query = [7 * y > 100, y < 20, 1000 * x > 30.5, x < 1]
    s = z3.Solver()
    s.add(*query)
    assert s.check() == z3.sat and not short(Fraction(str(s.model()[y]))), "Z3 answers with a rational here"
    nice = nicer_model(query, enc, {"A.out.y": "107/7", "A.in.x": "2061/4000"})
    assert nice.changed and nice.model["A.out.y"] == "15" and nice.model["A.in.x"] == "0.5"
    assert _holds(query, {y: nice.model["A.out.y"], x: nice.model["A.in.x"]})


def test_exact_values_are_kept_when_no_shorter_witness_exists() -> None:
    x = z3.Real("x")
    nice = nicer_model([3 * x == 7], _Enc((x, "A.in.x")), {"A.in.x": "7/3"})
    assert (nice.model, nice.changed) == ({"A.in.x": "7/3"}, False)


def test_a_model_already_short_and_within_is_returned_unchanged() -> None:
    d = z3.Int("d")
    model = {"B.in.d": "450"}
    nice = nicer_model([d > 400], _Enc((d, "B.in.d")), model, assumptions=[("B assumption 1", d <= 500)])
    assert (nice.model, nice.changed, nice.within) == (model, False, True)


def test_an_input_outside_an_assumption_is_moved_inside_or_named() -> None:
    d = z3.Int("d")
    enc = _Enc((d, "MissionPlanner.in.dest_id"))
    inside = nicer_model([d > 400], enc, {"MissionPlanner.in.dest_id": "501"},
                         assumptions=[("MissionPlanner assumption 1", d <= 500)])
    assert inside.within is True and 400 < int(inside.model["MissionPlanner.in.dest_id"]) <= 500
    outside = nicer_model([d > 600], enc, {"MissionPlanner.in.dest_id": "601"},
                          assumptions=[("MissionPlanner assumption 1", d <= 500)])
    assert (outside.within, outside.outside, outside.model) == (
        False, ["MissionPlanner assumption 1"], {"MissionPlanner.in.dest_id": "601"})


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    ws = tmp_path_factory.mktemp("robot")
    (ws / "contracts").mkdir()
    (ws / "contracts/robot.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN)
    w = Workspace(ws)
    return {r.id: check_requirement(r, w.checked, w.model, w.plan) for r in w.plan.requirements}


def check_requirement(*args: object, **kw: object) -> dict:
    """As the requirements stage checks one (stages/requirements.py): in a fresh Z3 context, so the
    counterexample is the one a run shows whichever test ran before in this process."""
    world.fresh()
    return _check_requirement(*args, **kw)  # type: ignore[arg-type]


def _values(rec: dict) -> dict[str, str]:
    return {f"{row['node']}.{k}": v for row in rec["counterexample"] for k, v in row["values"].items()}


def test_requirement_counterexamples_use_short_values(robot: dict[str, dict]) -> None:
    for rid in ("NEAR", "SLOW", "HIGH"):
        rec = robot[rid]
        assert rec["verdict"] == "refuted"
        vals = _values(rec)
        assert all(short(Fraction(v)) for v in vals.values()), (rid, vals)  # 107/7 on main: a witness 15 exists
        assert 100 < 7 * Fraction(vals["Source.out.gain"]) and Fraction(vals["Source.out.gain"]) < 20


def test_requirement_counterexample_within_the_assumptions_or_saying_why(robot: dict[str, dict]) -> None:
    high = robot["HIGH"]
    vals = _values(high)
    assert Fraction(vals["Planner.in.dest"]) <= 500 and Fraction(vals["Planner.in.gain"]) <= 19
    assert Fraction(vals["Planner.out.goal"]) >= 9 and "counterexample_note" not in high
    near = robot["NEAR"]  # a goal past 10 needs dest > 500: outside Planner's assumption, and said so
    assert Fraction(_values(near)["Planner.in.dest"]) > 500
    assert [r["text"] for r in near["outside_assumptions"]] == ["in.dest <= 500"]
    assert near["outside_assumptions"][0]["source"] == "contracts/robot.rcl:12:11"
    assert "needs an input outside Planner: in.dest <= 500" in near["counterexample_note"]


def test_a_side_condition_in_context_shows_the_nodes_it_involves() -> None:
    sc = {"id": "Controller.sc6", "node": "Controller", "links": ["Base.out.max_speed -> Controller.in.max_speed (...)"],
          "context": {"violated": ["Base"]},
          "model": {"Base.out.max_speed": "2", "Base.in.cmd_vel": "2.5", "Localiser.out.pose_x": "0",
                    "LidarDriver.in.range": "0", "MissionManager.out.goal_x": "0.5"}}
    shown = side_condition_view(SideConditionRow.of(complete(SideConditionRow, sc)))
    assert shown.model == {"Base.out.max_speed": "2", "Base.in.cmd_vel": "2.5"} and shown.model_hidden == 3


def test_a_temporal_trace_keeps_what_is_named_changes_or_never_answers() -> None:
    def step(i: int, goal: str) -> dict:
        return {"step": i, "nodes": [
            {"node": "Localiser", "values": {"answers": "True", "in.marker_x": "11", "out.pose_x": "11", "published": "True"}},
            {"node": "Mission", "values": {"heard.x": "True", "in.order_x": "12", "in.reached_x": "0", "out.goal_x": goal}},
            {"node": "Planner", "values": {"accepts": "True", "answers": "False", "in.goal_x": goal, "out.reached_x": "0"}}]}
    t = {"trace": [step(0, "-1"), step(1, "12"), step(2, "12")], "loop": 1,
         "missing_progress": [{"node": "Planner"}]}
    steps, hidden = trace_view(t, ["eventually Mission.in.reached_x == 12", "Mission.in.order_x == 12"])
    assert [r["node"] for r in steps[0]["nodes"]] == ["Mission", "Planner"]
    assert steps[1]["nodes"][0]["values"] == {"in.order_x": "12", "in.reached_x": "0", "out.goal_x": "12"}
    assert steps[1]["nodes"][1]["values"] == {"accepts": "True", "answers": "False", "in.goal_x": "12",
                                              "out.reached_x": "0"}
    assert hidden == 5  # Localiser's four, Mission's run flag


def test_the_warehouse_counterexamples_read_well(tmp_path: Path) -> None:
    """The bundled warehouse example: every refuted requirement's inputs
    within their assumptions (or the note), short values, the temporal
    trace cut below the cone's variables; its side conditions' values
    short and of the nodes they involve."""
    from rclverify.calculus.compose import compose_node
    from rclverify.report.cex_cone import with_trace_view
    ws = tmp_path / "warehouse"
    shutil.copytree(REPO / "examples/warehouse", ws, ignore=shutil.ignore_patterns("artifacts", "reports"))
    w = Workspace(ws)
    for req in w.plan.requirements:
        rec = with_trace_view(check_requirement(req, w.checked, w.model, w.plan))
        if rec["verdict"] != "refuted":
            continue
        if rec.get("counterexample"):
            vals = _values(rec)
            assert all(short(Fraction(v)) for v in vals.values() if v not in ("TRUE", "FALSE")), (req.id, vals)
            assert rec.get("counterexample_note") or not rec.get("outside_assumptions")
        t = rec.get("temporal")
        if t and t.get("trace"):
            full = {(r["node"], k) for st in t["trace"] for r in st["nodes"] for k in r["values"]}
            shown = {(r["node"], k) for st in t["shown"] for r in st["nodes"] for k in r["values"]}
            assert shown < full and len(shown) <= len(full) // 2, (req.id, len(shown), len(full))
    sc = next(s for s in compose_node(w.checked, w.model, "Controller").side_conditions if s.id == "Controller.sc2")
    assert sc.status == "failed" and sc.model is not None
    assert all(short(Fraction(v)) for v in sc.model.values()), sc.model  # 0.0305 and 30.5 on main: 1 and 1000 exist
    assert 1000 * Fraction(sc.model["LidarDriver.in.range"]) == Fraction(sc.model["LidarDriver.out.obstacle"]) > 30


def test_a_short_model_without_assumptions_costs_no_query(monkeypatch: pytest.MonkeyPatch) -> None:
    # the in-context step's local counterexample (every chain node's): nothing to move inside, nothing to shorten
    import rclverify.semantics.nicemodel as nm
    asked: list[int] = []
    real_check = nm.check
    monkeypatch.setattr(nm, "check", lambda s: asked.append(1) or real_check(s))
    x, y = z3.Real("x"), z3.Real("y")
    model = {"N0.in.x0": "1000", "N0.out.x1": "1001"}
    nice = nicer_model([x <= 1000, y <= x + 1, z3.Not(y <= 1000)], _Enc((x, "N0.in.x0"), (y, "N0.out.x1")), model)
    assert (nice.model, nice.changed, nice.within, asked) == (model, False, None, [])
    # a long value still gets its search (and only then its queries)
    nice = nicer_model([3 * x > 7, x < 3], _Enc((x, "A.in.x")), {"A.in.x": "22/9"})
    assert nice.changed and nice.model["A.in.x"] == "2.4" and asked
