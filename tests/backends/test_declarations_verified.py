"""Every declaration has a verifying backend (issue 64).

``initially``, ``progress`` and ``periodic`` are judged on recorded runs by
the monitors (backends/monitors/declarations.py), the verdict rows are
carried by the evidence records, and a requirement whose proof uses a
declaration reads ``met`` once the declaration's evidence is discharged
(calculus/requirements/rollup.py).  A two-node robot (Planner sends the goal on as
Base's target, Base drives there and reports its pose; Base publishes its
initial pose, answers within one step and refreshes its pose every 100 ms)
is green under ``rclverify verify --strict``; a run with a 260 ms gap in the
pose and a run in which Base leaves two targets unanswered are not.  The
bounded-progress verdict is compared with a brute-force enumeration of
windows on random runs.  Real Z3, the real pipeline.
"""
from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends.monitors.declarations import check_declarations
from rclverify.backends.monitors.periods import check_periods
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.calculus.requirements.rollup import declaration_statuses, roll_up
from rclverify.traces.events import Event
from rclverify.traces.mapping import TopicRule, load_rules

RCL = """node Planner {
  inputs( goal : INTEGER, pose : INTEGER )
  outputs( target : INTEGER )
  topics( std_msgs/Int64 goal matches(in.goal), std_msgs/Int64 pose matches(in.pose),
          std_msgs/Int64 target matches(out.target) )
  assume( 0 <= in.goal and in.goal <= 10 )
  assume( 0 <= in.pose and in.pose <= 10 )
  guarantee( out.target == in.goal )
  progress( within 0 steps )
}
node Base {
  inputs( target : INTEGER )
  outputs( pose : INTEGER )
  topics( std_msgs/Int64 target matches(in.target), std_msgs/Int64 pose matches(out.pose) )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( out.pose == in.target )
  initially( out.pose == 0 )
  progress( within 1 steps )
  periodic( out.pose, 100 ms )
}
"""
PLAN = """contracts: [contracts/r.rcl]
nodes:
  Planner:
    evidence:
      - backend: monitors
        mapping: mapping.yaml
        traces: [traces/run.jsonl]
  Base:
    evidence:
      - backend: monitors
        mapping: mapping.yaml
        traces: [traces/run.jsonl]
      - backend: property_tests
        implementation: nodes/base.py:base
        max_examples: 30
requirements:
  - id: ARRIVE
    text: the robot eventually arrives at the goal
    formal: "eventually Planner.in.pose == 7"
    assuming: "Planner.in.goal == 7"
"""
BASE = """def base(target: int) -> dict[str, int]:
    return {"pose": target}


base.initial = {"pose": 0}  # what it publishes when it starts
"""
# the last target and pose stand in for the answers to the last questions of the loop (docs/monitors.md)
MAPPING = "topics:\n  target: {fields: [data], state: true}\n  pose: {fields: [data], state: true}\n"


def _run(variant: str) -> list[dict[str, Any]]:
    """Base publishes its initial pose 0, the goal 7 comes, then target and
    pose alternate every 30 ms; ``gap``: one pose 200 ms late; ``late``: Base
    leaves two targets in a row unanswered."""
    rows: list[dict[str, Any]] = [{"topic": "pose", "time": 0.0, "data": 0}, {"topic": "goal", "time": 0.01, "data": 7}]
    t = 0.02
    for i in range(10):
        if variant == "late" and i == 4:
            for _ in range(2):
                rows += [{"topic": "target", "time": round(t, 3), "data": 7},
                         {"topic": "goal", "time": round(t + 0.01, 3), "data": 7}]
                t += 0.02
        rows.append({"topic": "target", "time": round(t, 3), "data": 7})
        t += 0.03 + (0.2 if variant == "gap" and i == 5 else 0)
        rows.append({"topic": "pose", "time": round(t, 3), "data": 7})
        t += 0.03
    return rows


def _workspace(root: Path, variant: str) -> Path:
    ws = root / variant
    (ws / "contracts").mkdir(parents=True)
    (ws / "traces").mkdir()
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "contracts/plan.yaml").write_text(PLAN)
    (ws / "mapping.yaml").write_text(MAPPING)
    (ws / "nodes").mkdir()
    (ws / "nodes/base.py").write_text(BASE)
    (ws / "traces/run.jsonl").write_text("".join(json.dumps(r) + "\n" for r in _run(variant)))
    return ws


@pytest.fixture(scope="module")
def verified(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[int, dict[str, Any], Path]]:
    out = {}
    for variant in ("correct", "gap", "late"):
        ws = _workspace(tmp_path_factory.mktemp("decl"), variant)
        rc = main(["verify", "--strict", "-w", str(ws)])
        out[variant] = (rc, json.loads((ws / "reports/assurance.json").read_text()), ws)
    return out


def _evidence(ws: Path, node: str) -> dict[str, Any]:
    return json.loads((ws / f"artifacts/evidence/{node}.g0.monitors.run_jsonl.json").read_text())


def test_a_correct_system_with_progress_and_periods_is_green_under_strict(verified: Any) -> None:
    rc, report, ws = verified["correct"]
    req = next(r for r in report["requirements"] if r["id"] == "ARRIVE")
    assert rc == 0 and (req["verdict"], req["status"]) == ("met", "discharged"), req["note"]
    assert req["check"]["temporal"]["status"] == "proved"
    used = {p["kind"] for p in req["check"]["used"]}
    assert {"progress", "initial value"} <= used  # the proof rests on the declarations, and they are evidenced
    rows = {r["declaration"]: r for r in _evidence(ws, "Base")["details"]["declarations"]}
    assert {k: r["verdict"] for k, r in rows.items()} == {"initially 1": "true", "progress": "true",
                                                          "periodic out.pose": "true"}
    assert rows["initially 1"]["reason"].endswith("out.pose = 0 (run.jsonl:1)")
    assert rows["progress"]["source"].endswith("r.rcl:18:3")
    tested = json.loads((ws / "artifacts/evidence/Base.g1.property_tests.e1.json").read_text())
    assert tested["status"] == "discharged"
    assert {r["declaration"]: r["verdict"] for r in tested["details"]["declarations"]} == {
        "initially 1": "true", "progress": "true"}
    planner = _evidence(ws, "Planner")["details"]["declarations"]
    assert [(r["declaration"], r["verdict"]) for r in planner] == [("progress", "true")]


def test_a_run_missing_a_period_is_not_green(verified: Any) -> None:
    rc, report, ws = verified["gap"]
    req = next(r for r in report["requirements"] if r["id"] == "ARRIVE")
    ev = _evidence(ws, "Base")
    assert rc == 1 and req["verdict"] != "met" and ev["status"] == "failed"
    assert "a gap of 260 ms" in ev["explanation"]
    row = next(r for r in ev["details"]["declarations"] if r["declaration"] == "periodic out.pose")
    assert row["verdict"] == "false" and "run.jsonl:14" in row["reason"]


def test_a_late_answer_is_not_green_and_names_the_inputs(verified: Any) -> None:
    rc, report, ws = verified["late"]
    req = next(r for r in report["requirements"] if r["id"] == "ARRIVE")
    ev = _evidence(ws, "Base")
    assert rc == 1 and req["verdict"] == "proved, evidence outstanding" and req["status"] == "failed"
    assert "Base progress (declaration, failed: 1 discharged, 1 failed of 2 records)" in req["note"]
    assert ev["status"] == "failed"
    assert ("Base declares progress( within 1 steps )" in ev["explanation"]
            and "between the input at run.jsonl:11 and the input at run.jsonl:15" in ev["explanation"])
    assert _evidence(ws, "Planner")["status"] == "discharged"  # Planner answered every goal: not blamed


# ---- the monitor on hand-made runs -------------------------------------------------------------------------

def _checked(decls: str) -> Any:
    text = RCL.replace("  initially( out.pose == 0 )\n  progress( within 1 steps )\n  periodic( out.pose, 100 ms )\n",
                       decls)
    return check([parse_text(text, "r.rcl")])


def _events(spec: str) -> list[Event]:
    """``t7`` a target of 7, ``p3`` a pose of 3, ``tx`` a target outside the assumption (42); 10 ms apart."""
    out = []
    for i, tok in enumerate(spec.split()):
        topic = {"t": "target", "p": "pose"}[tok[0]]
        out.append(Event(i, i * 0.01, topic, {"data": 42 if tok[1:] == "x" else int(tok[1:])}, f"run.jsonl:{i + 1}"))
    return out


def _verdicts(decls: str, spec: str) -> dict[str, tuple[str, str]]:
    c = _checked(decls)
    node = c.nodes["Base"]
    evs = _events(spec)
    res = check_declarations(c, node, evs, {}, check_periods(node, evs))
    return {r["declaration"]: (r["verdict"], r["reason"]) for r in res.rows()}


@pytest.mark.parametrize("spec, verdict, words", [
    ("p0 t7 p7", "true", "out.pose = 0 (run.jsonl:1)"),
    ("p5 t7 p7", "false", "do not satisfy it: out.pose = 5"),
    ("t7 p7", "inconclusive", "came after the input at run.jsonl:1: they may be the node's answer to it"),
    ("tx p0", "inconclusive", "came after the input at run.jsonl:1"),  # even true: an answer, not a start value
    ("t7 t7", "pending", "no message of out.pose"),
], ids=["first-holds", "first-wrong", "after-input", "after-input-true", "silent"])
def test_initially_is_judged_on_the_first_published_value(spec: str, verdict: str, words: str) -> None:
    got, reason = _verdicts("  initially( out.pose == 0 )\n", spec)["initially 1"]
    assert got == verdict and words in reason, reason


@pytest.mark.parametrize("decl, spec, verdict, words", [
    ("progress( within 1 steps )", "t7 t7 p7 t7 p7", "true", "3 accepted input events"),
    # an output heard first (p0): the answer's reader had matched, every step counts
    ("progress( within 1 steps )", "p0 t7 t7 t7 p7", "false", "2 accepted steps in a row unanswered"),
    ("progress( within 1 steps )", "t7 tx t7 p7", "true", ""),  # a refused input ends the row
    ("progress( within 0 steps )", "p0 t7 t7 p7", "false",
     "between the input at run.jsonl:2 and the input at run.jsonl:3"),
    ("progress( within 0 steps )", "tx tx p1", "pending", "nothing to answer"),
    ("progress( eventually )", "t7 t7 t7 p7", "true", ""),
    ("progress( eventually )", "t7 p7 t7", "inconclusive", "never refutes"),
    ("periodic( out.pose, 2 steps )", "p0 t7 t7 t7 p7", "false", "no message of out.pose"),
    # start-up: judging starts at the first answer heard; what came before is said, never counted
    ("progress( within 0 steps )", "t7 t7 p7 t7 p7", "true", "2 accepted input event(s) before the first output"),
    ("progress( within 0 steps )", "t7 t7", "inconclusive", "no output of the node was heard"),
], ids=["within-1", "within-1-broken", "refused-resets", "within-0-broken", "no-input", "eventually",
        "eventually-open", "periodic-steps", "start-up", "never-heard"])
def test_progress_counts_accepted_steps_until_an_answer(decl: str, spec: str, verdict: str, words: str) -> None:
    key = "progress" if decl.startswith("progress") else "periodic out.pose"
    got, reason = _verdicts(f"  {decl}\n", spec)[key]
    assert got == verdict and words in reason, reason


def test_a_period_in_time_needs_a_gap_to_be_shown() -> None:
    assert _verdicts("  periodic( out.pose, 100 ms )\n", "t7 p7")["periodic out.pose"][0] == "inconclusive"
    assert _verdicts("  periodic( out.pose, 100 ms )\n", "t7 p7 t7 p7")["periodic out.pose"][0] == "true"
    assert _verdicts("  periodic( out.pose, 100 ms )\n", "t7 t7")["periodic out.pose"][0] == "pending"


def _brute_force(steps: list[tuple[bool, bool]], k: int) -> bool:
    """Whether a run breaks ``progress( within k steps )``: some k + 1
    consecutive steps that are all accepted and unanswered, the last of them
    ended by a later input.  ``steps``: (accepted, answered) per input event,
    in order (the last step is open)."""
    closed = steps[:-1]
    return any(all(a and not ans for a, ans in closed[i:i + k + 1])
               for i in range(len(closed) - k))


def _judged_from(steps: list[tuple[bool, bool]], heard_first: bool) -> list[tuple[bool, bool]] | None:
    """The steps judging starts at: all when an output was heard before the first input, else those after
    the first answered one (its answer is the first output heard); ``None`` when no output was heard."""
    if heard_first:
        return steps
    first = next((i for i, (_, ans) in enumerate(steps) if ans), None)
    return None if first is None else steps[first + 1:]


def test_bounded_progress_agrees_with_brute_force_on_random_runs() -> None:
    rnd = random.Random(64)
    c = _checked("  progress( within 2 steps )\n")
    node = c.nodes["Base"]
    for _ in range(300):
        toks: list[str] = []
        steps: list[tuple[bool, bool]] = []
        for _ in range(rnd.randint(0, 9)):
            ok = rnd.random() < 0.8
            answered = rnd.random() < 0.4
            toks.append("t7" if ok else "tx")
            toks += ["p7"] * answered
            steps.append((ok, answered))
        heard_first = rnd.random() < 0.5
        toks = ["p0"] * heard_first + toks
        res = {r["declaration"]: r["verdict"] for r in check_declarations(c, node, _events(" ".join(toks)), {}).rows()}
        judged = _judged_from(steps, heard_first)
        want = _brute_force(judged, 2) if judged else False
        assert (res["progress"] == "false") == want, toks
        if not want:
            accepted = any(a for a, _ in steps)
            assert res["progress"] == ("pending" if not accepted else "inconclusive" if judged is None
                                       else "true"), toks


# ---- the roll-up ---------------------------------------------------------------------------------------------

def _record(kind: str = "progress") -> dict[str, Any]:
    return {"verdict": "proved", "consistency": "consistent", "vacuity": "non-vacuous",
            "used": [{"kind": kind, "label": "Base progress", "node": "Base", "index": 0}]}


@pytest.mark.parametrize("records, status, verdict", [
    ({}, "pending", "proved, evidence outstanding"),
    ({"Base": [("discharged", [{"declaration": "progress", "premise": "progress", "index": 0,
                                "status": "discharged"}])]}, "discharged", "met"),
    ({"Base": [("discharged", [{"declaration": "progress", "premise": "progress", "index": 0, "status": "pending"}]),
               ("discharged", [{"declaration": "progress", "premise": "progress", "index": 0,
                                "status": "discharged"}])]}, "discharged", "met"),
    ({"Base": [("failed", [{"declaration": "progress", "premise": "progress", "index": 0, "status": "failed"}]),
               ("discharged", [{"declaration": "progress", "premise": "progress", "index": 0,
                                "status": "discharged"}])]}, "failed", "proved, evidence outstanding"),
    ({"Base": [("stale", [{"declaration": "progress", "premise": "progress", "index": 0,
                           "status": "discharged"}])]}, "stale", "proved, evidence outstanding"),
    ({"Base": [("discharged", [{"declaration": "progress", "premise": "progress", "index": 0,
                                "status": "discharged"},
                               {"declaration": "periodic out.pose", "premise": "progress", "index": 0,
                                "status": "inconclusive"}])]}, "inconclusive", "proved, evidence outstanding"),
], ids=["none", "discharged", "one-run-exercised-it", "one-run-broke-it", "stale-record", "worst-of-two"])
def test_a_declaration_rolls_up_from_its_records(records: Any, status: str, verdict: str) -> None:
    got, words = declaration_statuses(records)("Base", "progress", 0)
    assert got == status
    v, s, note = roll_up(_record(), lambda n, k: "discharged", {}, "discharged", declaration_statuses(records))
    assert v == verdict and (s == "discharged") == (verdict == "met"), note
    if not records:
        assert "Base progress (declared, not verified)" in note


def test_an_input_no_clause_reads_is_not_a_step() -> None:
    """An action client's feedback, which its contract never reads, obliges
    no answer: ``within 0 steps`` holds on a run where the client answers
    every order but not the feedback in between."""
    c = check([parse_text("""node Client {
  inputs( order : INTEGER, feedback : INTEGER )
  outputs( goal : INTEGER )
  topics( std_msgs/Int64 order matches(in.order), std_msgs/Int64 feedback matches(in.feedback),
          std_msgs/Int64 goal matches(out.goal) )
  assume( 0 <= in.order )
  guarantee( out.goal == in.order )
  progress( within 0 steps )
}
""", "c.rcl")])
    topics = ["goal", "order", "goal", "feedback", "feedback", "order", "goal"]  # a goal heard first: judged from the start
    evs = [Event(i, i * 0.01, t, {"data": 3}, f"run.jsonl:{i + 1}") for i, t in enumerate(topics)]
    [row] = check_declarations(c, c.nodes["Client"], evs, {}).rows()
    assert (row["verdict"], row["reason"]) == ("true", "2 accepted input events, none left unanswered for more than 0 steps")
    late = evs[:2] + evs[3:]  # the first order never answered before the next
    [row] = check_declarations(c, c.nodes["Client"], late, {}).rows()
    assert row["verdict"] == "false" and "between the input at run.jsonl:2 and the input at run.jsonl:6" in row["reason"]


def test_the_monitor_command_and_the_live_run_judge_them_as_the_backend(verified: Any, tmp_path: Path,
                                                                        capsys: Any) -> None:
    """``rclverify monitor TRACE`` (exit 1 on the late answer) and the live
    run (:class:`LiveRun`, the messages pushed as the middleware hands them
    over) give the rows the backend's record has; the offline command on the
    live run's log gives them again (live = offline)."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.runtime.live import LiveRun
    checked = check([parse_text(RCL, "r.rcl")])
    for variant, code in (("correct", 0), ("late", 1)):
        ws = verified[variant][2]
        want = {r["declaration"]: r["verdict"] for r in _evidence(ws, "Base")["details"]["declarations"]}
        assert main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--json", str(ws / "traces/run.jsonl")]) == code
        offline = next(e for e in json.loads(capsys.readouterr().out) if "declarations" in e and e["node"] == "Base")
        cfg = load_mapping(ws, "mapping.yaml")
        log = tmp_path / f"{variant}.jsonl"
        live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, log, reorder_window=0.0)
        for row in _run(variant):
            live.tick(row["time"])
            live.push(row["topic"], {"data": row["data"]}, row["time"])
        rec = {e["node"]: e for e in live.stop()["declarations"]}
        assert main(["monitor", "-w", str(ws), "--mapping", "mapping.yaml", "--json", str(log)]) == code
        again = next(e for e in json.loads(capsys.readouterr().out) if "declarations" in e and e["node"] == "Base")
        for got in (rec["Base"]["declarations"], offline["declarations"], again["declarations"]):
            assert {r["declaration"]: r["verdict"] for r in got} == want
        assert rec["Base"]["status"] == offline["status"] == ("failed" if variant == "late" else "discharged")


# ---- the property tests ------------------------------------------------------------------------------------------

def test_the_property_tests_judge_progress_and_the_initial_value(tmp_path: Path) -> None:
    """An implementation that raises on an admissible input (target 10)
    breaks the declared progress; a class whose ``initial()`` gives pose 5
    breaks ``initially( out.pose == 0 )`` and fails the record of guarantee
    1; one without ``initial`` leaves it pending."""
    from rclverify.backends.property_tests.declared import declaration_rows
    from rclverify.backends.property_tests.harness import load_implementation, read_config, run_guarantee
    c = _checked("  initially( out.pose == 0 )\n  progress( within 0 steps )\n")
    node = c.nodes["Base"]
    (tmp_path / "impl.py").write_text(
        "def base(target):\n    if target == 10:\n        raise ValueError('no path to the end of the aisle')\n"
        "    return {'pose': target}\n\n\nclass Base:\n    def initial(self):\n        return {'pose': 5}\n\n"
        "    def step(self, target):\n        return {'pose': target}\n\n\ndef plain(target):\n    return {'pose': target}\n")
    rows = {}
    for attr in ("base", "Base", "plain"):
        cfg = read_config({"implementation": f"impl.py:{attr}", "max_examples": 50}, node, tmp_path)
        out = run_guarantee(c, node, 1, cfg, tmp_path)
        rows[attr] = {r["declaration"]: (r["verdict"], r["reason"]) for r in declaration_rows(
            c, node, load_implementation(tmp_path, cfg), out.status, out.counterexample, out.counts.valid)}
    assert rows["base"]["progress"][0] == "false" and "in.target = 10" in rows["base"]["progress"][1]
    assert rows["Base"]["progress"][0] == "true" and rows["plain"]["progress"][0] == "true"
    assert rows["Base"]["initially 1"] == ("false", "the implementation's initial outputs do not satisfy it: out.pose = 5")
    assert rows["plain"]["initially 1"][0] == "pending" and "no initial attribute" in rows["plain"]["initially 1"][1]
    assert rows["base"]["initially 1"][0] == "pending"


# ---- declarations that follow from others ------------------------------------------------------------------------

def test_an_initial_value_that_follows_from_another_rests_on_it() -> None:
    from rclverify.calculus.requirements.declared_proof import initial_support
    c = _checked("  initially( out.pose == 0 )\n  initially( out.pose <= 3 )\n  initially( out.pose * out.pose >= 0 )\n")
    node = c.nodes["Base"]
    assert initial_support(c, node, 2) == [1]  # pose == 0 entails pose <= 3
    assert initial_support(c, node, 3) == []  # holds of every integer
    assert initial_support(c, node, 1) is None  # pose <= 3 does not entail pose == 0
    row = {"declaration": "initially 1", "premise": "initial value", "index": 1, "status": "discharged"}
    d = declaration_statuses({"Base": [("discharged", [row])]}, c)
    assert d("Base", "initial value", 2) == ("discharged", "follows from initially 1 (Z3)")
    assert d("Base", "initial value", 3) == ("discharged", "holds of every value of its outputs' types (Z3)")
    assert d("Base", "initial value", 1)[0] == "discharged"
    pending = declaration_statuses({"Base": [("discharged", [{**row, "status": "inconclusive"}])]}, c)
    assert pending("Base", "initial value", 2)[0] == "pending"  # what it rests on is not verified


def test_entailment_of_initial_values_agrees_with_enumeration() -> None:
    """Random clauses over an output bounded by clause 1: Z3's entailment
    (initial_support) against the values -2..8 enumerated."""
    from rclverify.calculus.requirements.declared_proof import initial_support
    rnd = random.Random(640)
    ops = {"<=": lambda x, a: x <= a, ">=": lambda x, a: x >= a, "==": lambda x, a: x == a,
           "!=": lambda x, a: x != a, "<": lambda x, a: x < a}
    for _ in range(40):
        clauses = [("<=", 8), (">=", -2)] + [(rnd.choice(list(ops)), rnd.randint(-3, 9)) for _ in range(rnd.randint(1, 3))]
        text = "  initially( -2 <= out.pose and out.pose <= 8 )\n" + "".join(
            f"  initially( out.pose {op} {a} )\n" for op, a in clauses[2:])
        c = _checked(text)
        for goal in range(2, len(clauses)):
            others = [cl for k, cl in enumerate(clauses[2:], 2) if k != goal]
            domain = [x for x in range(-2, 9) if all(ops[op](x, a) for op, a in others)]
            op, a = clauses[goal]
            want = all(ops[op](x, a) for x in domain)
            got = initial_support(c, c.nodes["Base"], goal)
            assert (got is not None) == want, (text, goal)


def test_the_progress_premise_rests_on_the_least_bound() -> None:
    """``periodic( out.pose, 2 steps )`` (within 1 step) is the premise; the
    weaker ``progress( within 3 steps )`` follows from it, so its pending
    evidence does not hold the premise back; a failed one still fails it."""
    c = _checked("  progress( within 3 steps )\n  periodic( out.pose, 2 steps )\n")
    per = {"declaration": "periodic out.pose", "premise": "progress", "index": 0, "status": "discharged"}
    prog = {"declaration": "progress", "premise": "progress", "index": 0, "status": "pending"}
    d = declaration_statuses({"Base": [("discharged", [per, prog])]}, c)
    st, words = d("Base", "progress", 0)
    assert st == "discharged" and "progress follows from periodic out.pose" in words
    assert declaration_statuses({"Base": [("discharged", [per, prog])]})("Base", "progress", 0)[0] == "pending"
    failed = declaration_statuses({"Base": [("failed", [per, {**prog, "status": "failed"}])]}, c)
    assert failed("Base", "progress", 0)[0] == "failed"


def test_a_wrong_initial_value_fails_the_first_property_test_record(tmp_path: Path) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "nodes").mkdir()
    (ws / "contracts/r.rcl").write_text(RCL)
    (ws / "nodes/base.py").write_text(BASE.replace('{"pose": 0}', '{"pose": 4}'))
    (ws / "contracts/plan.yaml").write_text(
        "contracts: [contracts/r.rcl]\nnodes:\n  Base:\n    evidence:\n      - backend: property_tests\n"
        "        implementation: nodes/base.py:base\n        max_examples: 20\n")
    main(["verify", "-w", str(ws)])
    ev = json.loads((ws / "artifacts/evidence/Base.g1.property_tests.e0.json").read_text())
    assert ev["status"] == "failed", ev["explanation"]
    assert ev["explanation"].startswith("nodes/base.py:base declares initially( out.pose == 0 ) (")
    assert "do not satisfy it: out.pose = 4" in ev["explanation"]


def test_the_argument_has_a_goal_per_declaration_under_its_requirement(verified: Any) -> None:
    """Each declaration the proof used is a goal with its evidence, so the
    requirement's goal is never better than the declarations it rests on."""
    for variant, base_progress in (("correct", "discharged"), ("late", "failed")):
        ws = verified[variant][2]
        els = {e["id"]: e for e in json.loads((ws / "reports/argument.json").read_text())["elements"]}
        goals = {i: e["status"] for i, e in els.items() if i.startswith("G-decl.")}
        assert goals == {"G-decl.Planner_progress": "discharged", "G-decl.Base_initially_1": "discharged",
                         "G-decl.Base_progress": base_progress}, goals
        assert "G-decl.Base_progress" in els["S-ARRIVE"]["supported_by"]
        assert els["G-ARRIVE"]["status"] == ("discharged" if variant == "correct" else "failed")


def test_two_inputs_of_one_instant_are_one_step() -> None:
    """One upstream node publishes both inputs at once (1 ms apart, within the transport skew): one step,
    answered by one output; before, the first read as an unanswered step (a false alarm).  The control:
    the same inputs 100 ms apart, with no output between, are two steps."""
    c = check([parse_text("""node Mixer {
  inputs( a : INTEGER, b : INTEGER )
  outputs( y : INTEGER )
  topics( std_msgs/Int64 a matches(in.a), std_msgs/Int64 b matches(in.b), std_msgs/Int64 y matches(out.y) )
  assume( TRUE )
  guarantee( out.y == in.a + in.b )
  progress( within 0 steps )
}
""", "m.rcl")])
    rules = load_rules({})
    rules.skew = 0.02  # type: ignore[attr-defined]  # the mapping's transport skew (backends/monitors/skew.py)

    def run(gap: float) -> str:
        evs = [Event(0, 0.0, "y", {"data": 0}, "r:1"), Event(1, 1.0, "a", {"data": 1}, "r:2"),
               Event(2, 1.0 + gap, "b", {"data": 2}, "r:3"), Event(3, 1.2, "y", {"data": 3}, "r:4")]
        [row] = check_declarations(c, c.nodes["Mixer"], evs, rules).rows()
        return str(row["verdict"])
    assert run(0.001) == "true"
    assert run(0.1) == "false"
