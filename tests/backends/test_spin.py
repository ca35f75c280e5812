"""Stage two of the Agent's model checking: SPIN on an explored state graph (docs/model-checking.md).

Hand-built graphs stand for stage one's output; the case study's 39
instances need stage one (the Gwendolen explorer) and are skipped without it.
"""
from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

import pytest
import yaml

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.base import NodeTarget
from rclverify.backends.model_checking import backend as mc, spin_config
from rclverify.backends.model_checking import spin
from rclverify.backends.model_checking.graph import MentalState, StateGraph, Transition
from rclverify.backends.model_checking.ltl import Propositions, parse_psl_text, to_spin
from rclverify.backends.model_checking.promela import Claim, build_model
from rclverify.records.records import Obligation, SourceRef
from rclverify.model.plan.errors import PlanError

REPO = Path(__file__).resolve().parents[2]
HAVE_SPIN = shutil.which("spin") is not None and shutil.which("gcc") is not None
needs_spin = pytest.mark.skipif(not HAVE_SPIN, reason="spin or gcc not installed (apt-get install spin)")
SRC = "agent.gwen"


@pytest.fixture(autouse=True, scope="module")
def own_verifier_cache(tmp_path_factory: pytest.TempPathFactory):
    """The verifiers this module builds go to a cache of its own, not the user's."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("XDG_CACHE_HOME", str(tmp_path_factory.mktemp("xdg-cache")))
        yield


def t(text: str) -> psl.Term:
    f = psl.parse(f"P({text})")
    assert isinstance(f, psl.Percept)
    return f.term


def ms(*beliefs: str, action: str | None = None) -> MentalState:
    return MentalState(beliefs=frozenset(t(b) for b in beliefs), last_action=t(action) if action else None)


def rover(complete: bool = True) -> StateGraph:
    """Set off for waypoint 1; the move succeeds (inspect) or the radiation turns red (return)."""
    states = (
        ms(),                                                        # 0
        ms("going(1)"),                                              # 1
        ms("going(1)", "movebase_result(1, 3)"),                     # 2
        ms("going(1)", "movebase_result(1, 3)", action="inspect"),   # 3
        ms("going(1)", "movebase_result(1, 3)", "inspected(1)", action="inspect"),  # 4
        ms("going(1)", "danger_red"),                                # 5
        ms("going(1)", "danger_red", "going(0)"),                    # 6
    )
    transitions = (
        Transition(0, 1, "plan agent.gwen:72 +!inspect(1): deed +going(1)", 72, "D"),
        Transition(1, 2, "environment after move: asserts movebase_result(1, 3)", None, "env"),
        Transition(1, 5, "environment after move: asserts danger_red", None, "env"),
        Transition(2, 3, "plan agent.gwen:77 +movebase_result(1, 3): deed inspect", 77, "D"),
        Transition(3, 4, "plan agent.gwen:78 +movebase_result(1, 3): deed +inspected(1)", 78, "D"),
        Transition(5, 6, "plan agent.gwen:87 +danger_red: deed +going(0)", 87, "D"),
    )
    return StateGraph("jackal", SRC, states, transitions, complete=complete,
                      cut="" if complete else "states > 7", depth=4)


def looping() -> StateGraph:
    """Waiting for ever: 0 -> 1 -> 2 -> 1 ..., never inspected."""
    states = (ms(), ms("going(1)"), ms("going(1)", "waiting"))
    transitions = (Transition(0, 1, "plan agent.gwen:10 +!go: deed +going(1)", 10, "D"),
                   Transition(1, 2, "plan agent.gwen:12 +!wait: deed +waiting", 12, "D"),
                   Transition(2, 1, "plan agent.gwen:13 +!wait: deed -waiting", 13, "D"))
    return StateGraph("jackal", SRC, states, transitions)


RED = "[] (B(jackal, danger_red) -> <> B(jackal, going(0)))"
INSPECTED = "[] (B(jackal, going(1)) -> <> B(jackal, inspected(1)))"


def target_at(root: Path, config: dict | None = None) -> NodeTarget:
    return NodeTarget(root=root, checked=None, node=None, config=config or {},  # type: ignore[arg-type]
                      artifacts=root / "artifacts" / "ajpf" / "Agent")


def obligation(claim: str, text: str) -> Obligation:
    return Obligation(id=f"Agent.g0.ajpf.{claim}", node="Agent", guarantee=0, backend="ajpf",
                      kind="model checking", statement=text, source=SourceRef("p.psl", 1, 1),
                      data={"claim": claim, "psl": psl.to_text(psl.parse(text))})


def decide(tmp_path: Path, graph: StateGraph, texts: dict[str, str], claim: str):
    tools, why = spin.find_tools()
    assert tools is not None, why
    claims = [Claim(n, psl.parse(x)) for n, x in texts.items()]
    return mc.check_graph(obligation(claim, texts[claim]), target_at(tmp_path), graph, claims, claim, tools=tools,
                          graph_key=repr(graph), bounds=(100, 100), timeout_s=120)


# -- PSL -> SPIN LTL -------------------------------------------------------

@pytest.mark.parametrize("text, ltl", [
    ("T", "true"),
    ("F", "false"),
    ("B(jackal, going(1))", "q0"),
    ("P(danger_red)", "q0"),
    ("~B(jackal, going(1))", "! (q0)"),
    ("B(jackal, a) & G(jackal, b)", "(q0) && (q1)"),
    ("B(jackal, a) || D(jackal, inspect)", "(q0) || (q1)"),
    ("I(jackal, a) -> ItD(jackal, b)", "(q0) -> (q1)"),
    ("[] B(jackal, a)", "[] (q0)"),
    ("<> B(jackal, a)", "<> (q0)"),
    ("B(jackal, a) U B(jackal, b)", "(q0) U (q1)"),
    ("B(jackal, a) R B(jackal, b)", "(q0) V (q1)"),
    ("[] (B(jackal, danger_red) -> <> B(jackal, going(0)))", "[] ((q0) -> (<> (q1)))"),
    ("~(B(jackal, a) U ~B(jackal, a))", "! ((q0) U (! (q0)))"),
])
def test_psl_to_spin_ltl_each_operator(text: str, ltl: str) -> None:
    f = psl.parse(text)
    assert to_spin(f, Propositions([f])) == ltl


def test_propositions_are_named_once_in_order_of_use() -> None:
    a, b = psl.parse("B(jackal, x) & ~B(jackal, y)"), psl.parse("<> (B(jackal, y) || B(jackal, x))")
    props = Propositions([a, b])
    assert [(n, psl.to_text(atom)) for n, atom in props.atoms()] == [("q0", "B(jackal, x)"), ("q1", "B(jackal, y)")]
    assert to_spin(b, props) == "<> ((q1) || (q0))"


def test_property_file_errors_are_located() -> None:
    props = parse_psl_text("# c\n\nphi1: [] B(jackal, a)\nphi2 : <> ~P(b)\n", "f.psl")
    assert [(p.label, p.line, p.col) for p in props] == [("phi1", 3, 7), ("phi2", 4, 8)]
    with pytest.raises(PlanError) as e:
        parse_psl_text("phi1: [] B(jackal, a)\nphi1: <> B(jackal, a)\n", "f.psl")
    assert str(e.value).startswith("f.psl:2:1: error:") and "already used on line 1" in str(e.value)
    with pytest.raises(PlanError) as e:
        parse_psl_text("p: [] (B(jackal, a) -> )\n", "f.psl")
    assert str(e.value).startswith("f.psl:1:") and "expected a proposition" in str(e.value)
    with pytest.raises(PlanError) as e:
        parse_psl_text("[] B(jackal, a)\n", "f.psl")
    assert "expected '<label>: <formula>'" in str(e.value)


def test_authors_properties_file_parses() -> None:
    props = parse_psl_text((REPO / "backends/ajpf/authors.psl").read_text(), "backends/ajpf/authors.psl")
    labels = [p.label for p in props]
    assert labels[:13] == [f"phi1_{i}" for i in range(13)] and labels[-2:] == ["phi3a", "phi3b"]
    assert len(props) == 13 + 12 + 12 + 2


# -- the Promela model -----------------------------------------------------

def test_model_sets_each_proposition_where_the_graph_says() -> None:
    f = psl.parse(INSPECTED)
    text = build_model(rover(), [Claim("p1", f)]).text
    assert "ltl p1 { [] ((q0) -> (<> (q1))) }" in text
    assert "/* q0: B(jackal, going(1)) */" in text and "/* q1: B(jackal, inspected(1)) */" in text
    # into state 1 (2 successors) going(1) becomes true; into state 4 (final) inspected(1)
    assert ":: s == 0 -> s = 1; n = 2; q0 = 1; printf(\"@T 0\\n\")" in text
    assert ":: s == 3 -> s = 4; n = 0; q1 = 1; printf(\"@T 4\\n\")" in text
    assert "n == 0; printf(\"@S %d\\n\", s)" in text  # final states stutter


# -- SPIN verdicts on hand-built graphs -------------------------------------

@needs_spin
def test_property_that_holds_is_discharged(tmp_path: Path) -> None:
    ev = decide(tmp_path, rover(), {"red": RED, "insp": INSPECTED}, "red")
    assert ev.status == "discharged", ev.explanation
    assert "checked by SPIN on rclverify's exploration of the Gwendolen program agent.gwen" in ev.explanation
    assert "AJPF" not in ev.explanation and ev.tool == "SPIN" and ev.tool_version.startswith("Spin 6")
    assert ev.details["states"] == 7 and ev.details["transitions"] == 6 and ev.details["complete"] is True
    assert (tmp_path / "artifacts/ajpf/Agent/spin/model.pml").is_file()


@needs_spin
def test_violated_property_fails_with_the_lasso_mapped_to_source_lines(tmp_path: Path) -> None:
    ev = decide(tmp_path, rover(), {"red": RED, "insp": INSPECTED}, "insp")
    assert ev.status == "failed", ev.explanation
    cex = ev.details["lasso"]
    assert cex["kind"] == "lasso" and cex["source"] == SRC
    assert ev.counterexample == {"lasso": "a lasso of 3 steps then a cycle of 1; Gwendolen lines 72, 87 of agent.gwen",
                                 "trace": cex["trace"]}
    # the only violating path: set off, red radiation, head home -- and stay there (final state stutters)
    assert [s.get("transition") for s in cex["prefix"]] == [0, 2, 5]
    assert [(s["line"], s["stage"]) for s in cex["prefix"]] == [(72, "D"), (None, "env"), (87, "D")]
    assert [s["where"] for s in cex["prefix"]] == ["agent.gwen:72", "", "agent.gwen:87"]
    assert cex["cycle"] == [{"stutter": 6, "from": 6, "to": 6, "label": "state 6 is final: it stutters",
                             "line": None, "stage": "", "where": "", "holds": ["B(jackal, going(1))"]}]
    assert "Gwendolen lines 72, 87 of agent.gwen" in ev.explanation
    trail = (tmp_path / "artifacts/ajpf/Agent/spin/insp.trail.txt").read_text()
    assert "-- the cycle, repeated for ever, starts here --" in trail and "[agent.gwen:87, stage D]" in trail


@needs_spin
def test_violation_on_a_real_cycle(tmp_path: Path) -> None:
    ev = decide(tmp_path, looping(), {"w": "<> B(jackal, inspected(1))"}, "w")
    assert ev.status == "failed", ev.explanation
    cex = ev.details["lasso"]
    steps = cex["prefix"] + cex["cycle"]
    assert [s["transition"] for s in steps][:1] == [0]
    assert sorted(s["line"] for s in cex["cycle"]) == [12, 13]  # the loop 1 -> 2 -> 1, for ever


@needs_spin
def test_incomplete_graph_is_inconclusive_and_spin_is_not_run_on_it(tmp_path: Path) -> None:
    ev = decide(tmp_path, rover(complete=False), {"red": RED}, "red")
    assert ev.status == "inconclusive", ev.explanation
    assert "cut (states > 7)" in ev.explanation and "SPIN was not run" in ev.explanation
    assert ev.details["spin_verdict"] == "not run" and ev.details["bounded"] is True


def test_spin_missing_gives_pending_with_the_install_command(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    ev = mc.run_spin(obligation("red", RED), target_at(tmp_path), "agent.gwen", 10)
    assert ev.status == "pending"
    assert "spin and gcc not found on PATH" in ev.explanation and "apt-get install spin" in ev.explanation
    assert ev.tool_version == "not installed"


def test_default_checker_is_spin_only_without_mcapl_and_with_an_environment() -> None:
    env = {"environment": {"percepts": ["a"]}}
    assert spin_config.chosen_checker(env, {}) == "spin"
    assert spin_config.chosen_checker(env, {"MCAPL_HOME": "/opt/mcapl"}) == "ajpf"
    assert spin_config.chosen_checker({}, {}) == "ajpf"
    assert spin_config.chosen_checker({**env, "model_checker": "ajpf"}, {}) == "ajpf"
    assert spin_config.chosen_checker({"model_checker": "spin"}, {"MCAPL_HOME": "x"}) == "spin"


# -- the case study (needs stage one, the explorer) -------------------------

STAGE_ONE = importlib.util.find_spec("rclverify.backends.model_checking.explore") is not None


@needs_spin
@pytest.mark.skipif(not STAGE_ONE, reason="stage one not present")
def test_case_study_instances_all_decided(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
    from rclverify.stages.workspace import Workspace
    monkeypatch.delenv("MCAPL_HOME", raising=False)
    monkeypatch.delenv("AJPF_HOME", raising=False)
    plan = yaml.safe_load((REPO / "contracts/plan.yaml").read_text())
    entry = next(e for e in plan["nodes"]["Agent"]["evidence"] if e["backend"] == "ajpf")
    assert entry.get("model_checker") == "spin" and "environment" in entry
    entry = {**entry, "properties": ["backends/ajpf/authors.psl"]}
    for d in ("contracts", "backends/ajpf"):
        (tmp_path / d).mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "contracts/remote_inspection.rcl", tmp_path / "contracts")
    for f in ("jackal.gwen", "authors.psl"):
        shutil.copy(REPO / "backends/ajpf" / f, tmp_path / "backends/ajpf")
    (tmp_path / "contracts/plan.yaml").write_text(yaml.safe_dump(
        {"contracts": ["contracts/remote_inspection.rcl"], "nodes": {"Agent": {"evidence": [entry]}}}))
    target = Workspace(tmp_path).target("Agent", 0)
    obligations = AjpfBackend().export(target)
    derived = [o for o in obligations if o.guarantee > 0]
    authors = [o for o in obligations if o.guarantee == 0]
    assert len(derived) == 39 and len(authors) == 39
    mc.clear_caches()
    evs = [AjpfBackend().run(o, target) for o in obligations]
    assert all(e.status in ("discharged", "failed", "inconclusive") for e in evs), \
        [(e.obligation, e.status, e.explanation) for e in evs if e.status not in ("discharged", "failed")]
    for o, e in zip(obligations, evs):
        assert e.tool == "SPIN" and e.details["complete"] is True
        assert (e.status == "failed") == (e.details["spin_verdict"] == "violated")
        if e.status == "failed":
            assert e.counterexample["trace"] and e.details["lasso"]["prefix"][0]["from"] == 0
        if e.status == "inconclusive":  # partial coverage of a guarantee, or a vacuous pass, turns a verified one so
            assert e.details["spin_verdict"] == "holds"
            assert "PARTIAL COVERAGE" in e.explanation or "(vacuous)" in e.explanation, e.explanation
    by_label = {o.data["label"]: e for o, e in zip(authors, evs[len(derived):])}
    assert by_label["phi3a"].status == by_label["phi3b"].status == "discharged"
    # authors.psl says it: "as printed, phi_1^0 holds vacuously" (going(0) and ~going(0) at once)
    assert by_label["phi1_0"].status == "inconclusive" and by_label["phi1_0"].details["vacuous"]
    assert sorted(k for k, e in by_label.items() if e.details.get("vacuous")) == ["phi1_0"]
    assert len(mc._GRAPHS) == 1 and len(mc._MODELS) == 1  # one exploration, one verifier for all 78


# -- reading replays, plan keys ---------------------------------------------

def test_replay_text_is_read_and_checked_against_the_graph() -> None:
    from rclverify.backends.model_checking.trail import counterexample, read_replay
    text = "starting claim 2\n@T 0\n  2:\tproc  0 (agent:1) model.pml:20 ...\n@T 2\n<<<<<START OF CYCLE>>>>>\n@T 5\n@S 6\n"
    replay = read_replay(text)
    assert replay.steps == (("T", 0), ("T", 2), ("T", 5), ("S", 6)) and replay.cycle_start == 2
    cex = counterexample(rover(), replay)
    assert [s["to"] for s in cex["prefix"]] == [1, 5] and [s["to"] for s in cex["cycle"]] == [6, 6]
    with pytest.raises(ValueError, match="takes transition 3 from state 2, but is in state 1"):
        counterexample(rover(), read_replay("@T 0\n@T 3\n"))
    with pytest.raises(ValueError, match="names transition 99"):
        counterexample(rover(), read_replay("@T 99\n"))


PLAN_SPIN = """\
contracts:
  - contracts/remote_inspection.rcl
nodes:
  Agent:
    evidence:
      - backend: ajpf
        agent: jackal
        model: backends/ajpf/jackal.gwen
        domains: {{i: [0, 12]}}
{extra}"""


def spin_workspace(root: Path, extra: str) -> NodeTarget:
    from rclverify.stages.workspace import Workspace
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "backends/ajpf").mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "contracts/remote_inspection.rcl", root / "contracts")
    shutil.copy(REPO / "backends/ajpf/jackal.gwen", root / "backends/ajpf")
    (root / "contracts/plan.yaml").write_text(PLAN_SPIN.format(extra=extra))
    return Workspace(root).target("Agent", 0)


@pytest.mark.parametrize("extra, where, message", [
    ("        model_checker: nusmv\n", 10, "'model_checker' must be one of spin, ajpf"),
    ("        model_checker: spin\n", 10, "model_checker spin needs an 'environment'"),
    ("        max_states: 0\n", 10, "'max_states' must be a positive integer"),
    ("        properties: [backends/ajpf/none.psl]\n", 10, "property file 'backends/ajpf/none.psl' does not exist"),
])
def test_spin_keys_are_checked_with_located_errors(tmp_path: Path, extra: str, where: int, message: str) -> None:
    from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
    target = spin_workspace(tmp_path, extra)
    with pytest.raises(PlanError) as e:
        AjpfBackend().export(target)
    assert str(e.value).startswith(f"contracts/plan.yaml:{where}:") and message in str(e.value)


def test_property_files_give_obligations_of_their_own(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
    monkeypatch.delenv("MCAPL_HOME", raising=False)
    monkeypatch.delenv("AJPF_HOME", raising=False)
    (tmp_path / "backends/ajpf").mkdir(parents=True)
    (tmp_path / "backends/ajpf/extra.psl").write_text("# mine\nsafe: [] ~B(jackal, danger_red)\n")
    target = spin_workspace(tmp_path, "        properties: [backends/ajpf/extra.psl]\n")
    obs = AjpfBackend().export(target)
    [extra] = [o for o in obs if o.guarantee == 0]
    assert extra.id == "Agent.g0.ajpf.extra_safe" and extra.statement == "safe: [] ~B(jackal, danger_red)"
    assert (extra.source.file, extra.source.line, extra.source.col) == ("backends/ajpf/extra.psl", 2, 7)
    assert extra.data["claim"] == "x0_safe" and "backends/ajpf/extra.psl" in extra.inputs
    # no environment declared: the AJPF runner is the default, and it checks agent.psl only
    ev = AjpfBackend().run(extra, target)
    assert ev.status == "pending" and "model_checker: spin" in ev.explanation
    (tmp_path / "backends/ajpf/extra.psl").write_text("safe: [] ~B(jackal danger_red)\n")
    with pytest.raises(PlanError) as e:
        AjpfBackend().export(target)
    assert str(e.value).startswith("backends/ajpf/extra.psl:1:")


@needs_spin
def test_safety_violation_is_a_finite_bad_prefix(tmp_path: Path) -> None:
    ev = decide(tmp_path, rover(), {"safe": "[] ~B(jackal, danger_red)"}, "safe")
    assert ev.status == "failed", ev.explanation
    lasso = ev.details["lasso"]
    assert lasso["kind"] == "prefix" and lasso["cycle"] == []
    assert ev.counterexample["lasso"] == ("a path of 2 steps after which the property cannot hold; "
                                          "Gwendolen line 72 of agent.gwen")
    assert [s["to"] for s in lasso["prefix"]][-1] == 5  # the first state believing danger_red
    assert lasso["prefix"][-1]["holds"] == ["B(jackal, danger_red)"]


@needs_spin
def test_a_search_cut_by_pan_s_depth_bound_is_incomplete(tmp_path: Path) -> None:
    tools, _ = spin.find_tools()
    assert tools is not None
    model = build_model(looping(), [Claim("w", psl.parse("[] ~B(jackal, inspected(1))"))])
    built = spin.compile_model(tools, model.text, tmp_path / "build")
    res = spin.check(tools, built, "w", max_depth=2, timeout_s=60)
    assert res.verdict == "incomplete" and "search depth bound 2" in res.reason
    assert spin.check(tools, built, "w", max_depth=1000, timeout_s=60).verdict == "holds"
