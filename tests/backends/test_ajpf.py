"""Tests of the AJPF backend: mapping, instantiation, .psl/.jpf rendering,
pending evidence without MCAPL, import of AJPF logs and staleness."""
from __future__ import annotations

import re
import shutil
from pathlib import Path
from typing import Iterator

import pytest
from rclverify.app.pipeline import Workspace

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.ajpf.backend import AjpfBackend
from rclverify.backends.model_checking.ajpf.instantiate import Translator
from rclverify.backends.model_checking.ajpf.mapping import Canon, Row, RowError, build_row, dnf
from rclverify.backends.model_checking.ajpf.results import parse_log
from rclverify.backends.base import NodeTarget
from rclverify.records.records import Obligation
from rclverify.records.store import EvidenceStore
from rclverify.model.plan.errors import PlanError
from rclverify.lang.parser import parse_formula

REPO = Path(__file__).resolve().parents[2]

# The plan entry proposed for the case study (paper table, lines 1396-1412,
# plus `when` rows deciding "is there a waypoint i" for the 13-waypoint map).
ROWS_YAML = """\
          - rcl: "in.at(x', y') == TRUE and in.wayP(x', y') == i"
            ajpf: "B(jackal, going({i})) & B(jackal, movebase_result(_, 3))"
          - rcl: "in.inspected(i) == TRUE"
            ajpf: "B(jackal, inspected({i}))"
          - rcl: "in.radiationStatus !in {red, orange}"
            ajpf: "~B(jackal, danger_red) & ~B(jackal, danger_orange)"
          - rcl: "in.radiationStatus in {red, orange}"
            ajpf: "B(jackal, danger_red) || B(jackal, danger_orange)"
          - rcl: "in.wayP(x, y) == i and out.command == move(x, y)"
            when: "i <= 12"
            ajpf: "B(jackal, going({i}))"
          - rcl: "in.wayP(x, y) == i and out.command == move(x, y)"
            when: "i > 12"
            ajpf: "F"
          - rcl: "forall(x'', y'' in REAL | in.wayP(x'', y'') != i)"
            when: "i > 12"
            ajpf: "T"
          - rcl: "forall(x'', y'' in REAL | in.wayP(x'', y'') != i)"
            when: "i <= 12"
            ajpf: "F"
          - rcl: "out.command == inspect(i)"
            ajpf: "D(jackal, inspect)"
"""

PLAN_TEMPLATE = """\
contracts:
  - contracts/remote_inspection.rcl
nodes:
  Agent:
    evidence:
      - backend: ajpf
        agent: jackal
        model: backends/ajpf/jackal.gwen
        domains: {{i: [0, 12]}}
        environment_class: gwendolen.compositional.rain.remote_inspection.RemoteInspectionVerificationEnv
        mapping:
{rows}"""

PHI_1_4 = ("[] ((B(jackal, going(4)) & B(jackal, movebase_result(_, 3)) & B(jackal, inspected(4)) & "
           "~B(jackal, danger_red) & ~B(jackal, danger_orange)) -> <> B(jackal, going(5)))")


def make_target(root: Path, rows: str = ROWS_YAML, monkeypatch: pytest.MonkeyPatch | None = None) -> NodeTarget:
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "backends" / "ajpf").mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "contracts" / "remote_inspection.rcl", root / "contracts" / "remote_inspection.rcl")
    shutil.copy(REPO / "backends" / "ajpf" / "jackal.gwen", root / "backends" / "ajpf" / "jackal.gwen")
    plan_text = PLAN_TEMPLATE.format(rows=rows)
    (root / "contracts" / "plan.yaml").write_text(plan_text, encoding="utf-8")
    return Workspace(root).target("Agent", 0)  # as the pipeline builds it, with the plan's locations


@pytest.fixture
def no_mcapl(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("MCAPL_HOME", raising=False)
    monkeypatch.delenv("AJPF_HOME", raising=False)


def _by_id(obligations: list[Obligation]) -> dict[str, Obligation]:
    return {o.id: o for o in obligations}


def verified_log(n: int, text: str) -> str:
    return f"""\
JavaPathfinder core system v8.0 - (C) 2005-2014 United States Government. All rights reserved.


====================================================== system under test
ail.util.AJPF_w_AIL.main("artifacts/ajpf/Agent/agent.ail","artifacts/ajpf/Agent/agent.psl","{n}")

====================================================== search started: 02/03/24 10:00
MCAPL Framework 2020
[INFO]  {text}
[INFO] Adding 0 to []
[INFO] jackal done move(3.0,1.5,0.0)
[INFO] Adding 1 to [0]
[INFO] Always True from Now On

====================================================== results
no errors detected

====================================================== statistics
elapsed time:       00:03:12
states:             new=5123,visited=817,backtracked=5940,end=14
search:             maxDepth=204,constraints=0
max memory:         1024MB

====================================================== search finished: 02/03/24 10:03
"""


def violated_log(n: int, text: str) -> str:
    return f"""\
JavaPathfinder core system v8.0 - (C) 2005-2014 United States Government. All rights reserved.

====================================================== system under test
ail.util.AJPF_w_AIL.main("artifacts/ajpf/Agent/agent.ail","artifacts/ajpf/Agent/agent.psl","{n}")

====================================================== search started: 02/03/24 11:00
MCAPL Framework 2020
[INFO]  {text}
[INFO] Adding 0 to []
[INFO] jackal done move(3.0,1.5,0.0)
[INFO] Adding 1 to [0]
[INFO] jackal done inspect
[INFO] Adding 2 to [0, 1]
[INFO] Adding 3 to [0, 1, 2]

====================================================== error 1
ajpf.MCAPLListener
An Accepting Path has been found: 
[MS: 0, BS: 2, UN: 0], [MS: 1, BS: 2, UN: 0], [MS: 2, BS: 3, UN: 0],
[MS: 3, BS: 3, UN: 0], 

====================================================== snapshot #1
no live threads

====================================================== results
error #1: ajpf.MCAPLListener "An Accepting Path has been found:  [MS: 0, BS: 2, ..."

====================================================== statistics
elapsed time:       00:00:41
states:             new=40,visited=3,backtracked=12,end=0
search:             maxDepth=4,constraints=0

====================================================== search finished: 02/03/24 11:01
"""


# ---------------------------------------------------------------------------
# PSL
# ---------------------------------------------------------------------------


def test_psl_round_trip_and_negation_normal_form() -> None:
    f = psl.parse("[] ((B(jackal, going(4)) & ~B(jackal, danger_red)) -> <> D(jackal, inspect))")
    assert psl.parse(psl.to_text(f)) == f
    neg = psl.negate(f)
    # ~[](a -> <>b) == <>(a & []~b), negations only on propositions
    assert psl.to_text(psl.simplify(neg)) == ("<> (B(jackal, going(4)) & ~B(jackal, danger_red) & "
                                              "[] ~D(jackal, inspect))")
    assert isinstance(neg, psl.Eventually)
    assert psl.to_text(psl.simplify(psl.negate(neg))) == (
        "[] (~B(jackal, going(4)) || B(jackal, danger_red) || <> D(jackal, inspect))")
    assert all(not isinstance(x, psl.Not) or isinstance(x.operand, (psl.Modal, psl.Percept))
               for x in _walk(neg))


def _walk(f: psl.Formula) -> Iterator[psl.Formula]:
    yield f
    for attr in ("operand", "left", "right"):
        if hasattr(f, attr):
            yield from _walk(getattr(f, attr))
    for p in getattr(f, "parts", ()):
        yield from _walk(p)


def test_psl_rejects_ambiguous_and_non_ground_text() -> None:
    with pytest.raises(psl.PslSyntaxError, match="mixed"):
        psl.parse("B(a, x) & B(a, y) || B(a, z)")
    with pytest.raises(psl.PslSyntaxError, match="chained"):
        psl.parse("B(a, x) -> B(a, y) -> B(a, z)")
    with pytest.raises(psl.PslSyntaxError, match="variable"):
        psl.parse("B(a, going(X))")
    assert psl.to_text(psl.parse("(B(a, x) & B(a, y)) || B(a, z)")) == "(B(a, x) & B(a, y)) || B(a, z)"


def test_psl_simplify_folds_constants() -> None:
    f = psl.parse("[] ((B(a, x) || F) -> <> (B(a, y) || (F & B(a, z))))")
    assert psl.to_text(psl.simplify(f)) == "[] (B(a, x) -> <> B(a, y))"
    assert psl.to_text(psl.simplify(psl.parse("[] (T -> <> B(a, y))"))) == "[] <> B(a, y)"
    assert psl.simplify(psl.parse("[] (F -> <> B(a, y))")) == psl.TRUE


# ---------------------------------------------------------------------------
# Mapping rows and matching
# ---------------------------------------------------------------------------

FIXED = {"red", "orange", "green"}
IO = {"wayP": "in", "at": "in", "radiationStatus": "in", "inspected": "in", "command": "out"}


def _row(k: int, rcl: str, ajpf: str, when: str | None = None) -> Row:
    raw = {"rcl": rcl, "ajpf": ajpf}
    if when is not None:
        raw["when"] = when
    return build_row(k, raw, dom_names={"i"}, fixed=FIXED, io=IO, agent="jackal")


def test_row_matches_subconjunction_modulo_variable_names() -> None:
    move = _row(0, "in.wayP(x, y) == i and out.command == move(x, y)", "B(jackal, going({i}))")
    tr = Translator([move], {"i": (0, 12)}, FIXED, IO)
    # the row is written with x, y; the guarantee uses x'', y'', operands swapped, value 0
    goal = parse_formula("exists(x'', y'' in REAL | out.command == move(x'', y'') and 0 == in.wayP(x'', y''))")
    ((items, evars),) = list(dnf(Canon(IO).form(goal)))
    apps, skipped, _ = tr.cover(items, evars, {})
    assert skipped == [] and len(apps) == 1
    assert psl.to_text(apps[0].formula) == "B(jackal, going(0))"
    # i + 1 with i = 4 gives 5
    goal = parse_formula("exists(x, y in REAL | in.wayP(x, y) == i + 1 and out.command == move(x, y))")
    ((items, evars),) = list(dnf(Canon(IO).form(goal)))
    apps, skipped, _ = tr.cover(items, evars, {"i": 4})
    assert psl.to_text(apps[0].formula) == "B(jackal, going(5))"


def test_existential_variable_must_be_covered_by_one_row() -> None:
    # two rows each covering one of two atoms sharing x, y would split the
    # existential: exists v (A(v) and B(v)) is not (exists v A) and (exists v B)
    way = _row(0, "in.wayP(x, y) == i", "B(jackal, going({i}))")
    cmd = _row(1, "out.command == move(x, y)", "D(jackal, move(_, _, _))")
    tr = Translator([way, cmd], {"i": (0, 12)}, FIXED, IO)
    goal = parse_formula("exists(x, y in REAL | in.wayP(x, y) == 3 and out.command == move(x, y))")
    ((items, evars),) = list(dnf(Canon(IO).form(goal)))
    apps, skipped, _ = tr.cover(items, evars, {})
    assert apps == [] and skipped == [0, 1]
    both = _row(2, "in.wayP(x, y) == i and out.command == move(x, y)", "B(jackal, going({i}))")
    apps, skipped, _ = Translator([way, cmd, both], {"i": (0, 12)}, FIXED, IO).cover(items, evars, {})
    assert skipped == [] and [a.row.index for a in apps] == [2]


def test_negated_atom_is_covered_by_negating_a_one_atom_row() -> None:
    insp = _row(0, "in.inspected(i) == TRUE", "B(jackal, inspected({i}))")
    tr = Translator([insp], {"i": (0, 12)}, FIXED, IO)
    ((items, evars),) = list(dnf(Canon(IO).form(parse_formula("in.inspected(i) == FALSE"))))
    apps, skipped, _ = tr.cover(items, evars, {"i": 7})
    assert skipped == [] and apps[0].negated
    assert psl.to_text(apps[0].formula) == "~B(jackal, inspected(7))"


def test_bad_rows_are_rejected() -> None:
    with pytest.raises(RowError, match="agent"):
        _row(0, "in.inspected(i) == TRUE", "B(robot, inspected({i}))")
    with pytest.raises(RowError, match="conjunction"):
        _row(0, "in.inspected(i) == TRUE or in.inspected(i + 1) == TRUE", "B(jackal, x)")
    with pytest.raises(RowError, match="placeholder"):
        _row(0, "in.radiationStatus in {red}", "B(jackal, going({i}))")


# ---------------------------------------------------------------------------
# Export: instantiation, .psl, .jpf
# ---------------------------------------------------------------------------


def test_one_property_per_waypoint_for_guarantees_1_and_2(tmp_path: Path) -> None:
    target = make_target(tmp_path)
    obs = AjpfBackend().export(target)
    for g in (1, 2):
        mine = [o for o in obs if o.guarantee == g]
        assert sorted(o.data["instance"]["i"] for o in mine) == list(range(13))
        numbers = [o.data["property"] for o in mine]
        assert len(set(numbers)) == 13  # a distinct property per waypoint
    text = (tmp_path / "artifacts/ajpf/Agent/agent.psl").read_text()
    props = dict(re.findall(r"^(\d+): (.*)$", text, re.MULTILINE))
    g1 = [o for o in obs if o.guarantee == 1]
    for o in g1:
        i = o.data["instance"]["i"]
        assert props[str(o.data["property"])] == o.data["psl"]
        assert f"B(jackal, going({i})) & B(jackal, movebase_result(_, 3))" in o.data["psl"]
        assert o.data["psl"].endswith(f"<> B(jackal, going({i + 1 if i < 12 else 0})))")
    for o in (o for o in obs if o.guarantee == 2):
        i = o.data["instance"]["i"]
        assert f"~B(jackal, inspected({i}))" in o.data["psl"]
        assert o.data["psl"].endswith("-> <> D(jackal, inspect))")
    # every property line is preceded by a comment naming guarantee, location and instance
    assert "# Agent guarantee 1 (contracts/remote_inspection.rcl:64:3), instance i=4\n5: " in text


def test_phi_1_4_text_and_jpf(tmp_path: Path) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    assert ob.data["psl"] == PHI_1_4
    assert ob.statement == "5: " + PHI_1_4
    assert ob.source.line == 64 and ob.instance == "i=4"
    psl_text = (tmp_path / "artifacts/ajpf/Agent/agent.psl").read_text()
    assert f"\n5: {PHI_1_4}\n" in psl_text
    jpf = (tmp_path / "artifacts/ajpf/Agent/agent_5.jpf").read_text()
    assert jpf.startswith("# generated by rclverify from contracts/remote_inspection.rcl:")
    assert "target = ail.util.AJPF_w_AIL\n" in jpf
    assert "target.args = artifacts/ajpf/Agent/agent.ail,artifacts/ajpf/Agent/agent.psl,5\n" in jpf
    assert "@using = mcapl" in jpf
    ail = (tmp_path / "artifacts/ajpf/Agent/agent.ail").read_text()
    assert "mas.file = backends/ajpf/jackal.gwen" in ail
    assert ob.inputs == ("backends/ajpf/jackal.gwen", "artifacts/ajpf/Agent/agent.psl",
                         "artifacts/ajpf/Agent/agent_5.jpf", "artifacts/ajpf/Agent/agent.ail",
                         "backends/ajpf/results/Agent/agent_5.log")


def test_guarantee_3_exposes_the_last_waypoint_instance(tmp_path: Path) -> None:
    obs = AjpfBackend().export(make_target(tmp_path))
    g3 = {o.data["instance"]["i"]: o for o in obs if o.guarantee == 3}
    assert g3[4].data["psl"] == "[] ((B(jackal, danger_red) || B(jackal, danger_orange)) -> <> B(jackal, going(0)))"
    assert g3[4].data["property"] == g3[0].data["property"]  # identical formulas share one property
    # there is no waypoint 13, so the guarantee as written demands heading for 0 always eventually
    assert g3[12].data["psl"] == "[] <> B(jackal, going(0))"


def test_export_is_deterministic_and_free_of_machine_paths(tmp_path: Path) -> None:
    target = make_target(tmp_path)
    AjpfBackend().export(target)
    art = tmp_path / "artifacts/ajpf/Agent"
    first = {p.name: p.read_bytes() for p in sorted(art.iterdir())}
    AjpfBackend().export(target)
    assert {p.name: p.read_bytes() for p in sorted(art.iterdir())} == first
    for data in first.values():
        assert str(tmp_path).encode() not in data


def test_unmapped_atoms_are_recorded_not_invented(tmp_path: Path, no_mcapl: None) -> None:
    rows = "\n".join(line for line in ROWS_YAML.splitlines()
                     if "inspected" not in line) + "\n"
    target = make_target(tmp_path, rows)
    obs = AjpfBackend().export(target)
    g1 = [o for o in obs if o.guarantee == 1]
    g2 = [o for o in obs if o.guarantee == 2]
    assert len(g1) == 13 and all("property" not in o.data for o in g1)
    assert g1[0].data["unmapped"] == ["in.inspected(i) == TRUE"]
    assert g2[3].data["unmapped"] == ["in.inspected(i) == FALSE"]
    assert g2[3].id == "Agent.g2.ajpf.unmapped_i3"
    assert g1[0].data["guarantee_unmapped"] == ["in.inspected(i) == TRUE"]
    # guarantee 3 is unaffected
    assert all("property" in o.data for o in obs if o.guarantee == 3)
    text = (tmp_path / "artifacts/ajpf/Agent/agent.psl").read_text()
    assert "# Agent guarantee 2 (contracts/remote_inspection.rcl:69:3), instance i=3: in.inspected(i) == FALSE" in text
    assert not re.search(r"^\d+: .*inspected", text, re.MULTILINE)
    ev = AjpfBackend().run(g2[3], target)
    assert ev.status == "pending"
    assert "in.inspected(i) == FALSE" in ev.explanation


def test_bad_row_is_a_located_plan_error(tmp_path: Path) -> None:
    rows = ROWS_YAML.replace("ajpf: \"D(jackal, inspect)\"", "ajpf: \"D(jackal, inspect\"")
    target = make_target(tmp_path, rows)
    with pytest.raises(PlanError) as exc:
        AjpfBackend().export(target)
    diag = exc.value.diagnostics[0]
    plan_lines = (tmp_path / "contracts/plan.yaml").read_text().splitlines()
    assert diag.loc.file == "contracts/plan.yaml"
    assert "D(jackal, inspect" in plan_lines[diag.loc.line - 1]
    assert "mapping row 9" in diag.message


def test_missing_model_is_a_plan_error(tmp_path: Path) -> None:
    target = make_target(tmp_path)
    (tmp_path / "backends/ajpf/jackal.gwen").unlink()
    with pytest.raises(PlanError, match="does not exist"):
        AjpfBackend().export(target)


# ---------------------------------------------------------------------------
# Evidence: pending, import, staleness
# ---------------------------------------------------------------------------


def test_pending_with_command_when_mcapl_absent(tmp_path: Path, no_mcapl: None) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    ev = AjpfBackend().run(ob, target)
    assert ev.status == "pending"
    assert "AJPF (MCAPL) not installed" in ev.explanation
    assert ("java -jar <MCAPL_HOME>/lib/3rdparty/RunJPF.jar artifacts/ajpf/Agent/agent_5.jpf "
            "> backends/ajpf/results/Agent/agent_5.log 2>&1") in ev.explanation


def test_mcapl_home_without_runjpf_is_not_an_installation(tmp_path: Path, no_mcapl: None,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    target = make_target(tmp_path)
    fake_home = tmp_path / "not-mcapl"
    fake_home.mkdir()
    monkeypatch.setenv("MCAPL_HOME", str(fake_home))
    ob = _by_id(AjpfBackend().export(target))["Agent.g2.ajpf.p18_i4"]
    ev = AjpfBackend().run(ob, target)
    assert ev.status == "pending"
    assert "MCAPL_HOME points at a directory without lib/3rdparty/RunJPF.jar" in ev.explanation


def _place_log(target: NodeTarget, n: int, text: str) -> None:
    p = target.root / "backends/ajpf/results/Agent" / f"agent_{n}.log"
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text, encoding="utf-8")


def test_import_verified_log_discharges(tmp_path: Path, no_mcapl: None) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    _place_log(target, 5, verified_log(5, PHI_1_4))
    ev = AjpfBackend().run(ob, target)
    # verified, but rows 7/8 map "there is no waypoint i + 1" to a constant: partial coverage
    # of guarantee 1, so not discharged (full coverage: tests/backends/test_findings_ajpf.py)
    assert ev.status == "inconclusive", ev.explanation
    assert "AJPF verified the property" in ev.explanation and "PARTIAL COVERAGE" in ev.explanation
    assert ev.tool_version == "MCAPL 2020, JPF 8.0"
    assert set(ev.input_hashes) == set(ob.inputs)
    assert ev.input_hashes["backends/ajpf/results/Agent/agent_5.log"] != "missing"
    # the same log does not discharge another property
    other = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p6_i5"]
    _place_log(target, 6, verified_log(5, PHI_1_4))
    assert AjpfBackend().run(other, target).status == "pending"


def test_import_violated_log_fails_with_path(tmp_path: Path, no_mcapl: None) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    _place_log(target, 5, violated_log(5, PHI_1_4))
    ev = AjpfBackend().run(ob, target)
    assert ev.status == "failed"
    assert ev.counterexample is not None
    assert ev.counterexample["accepting_path"] == ["MS 0, BS 2, UN 0", "MS 1, BS 2, UN 0", "MS 2, BS 3, UN 0",
                                                   "MS 3, BS 3, UN 0"]
    assert ev.counterexample["trace"][1] == "state 1: jackal done move(3.0,1.5,0.0)"
    assert ev.counterexample["trace"][2] == "state 2: jackal done inspect"


def test_log_of_an_older_property_text_is_stale(tmp_path: Path, no_mcapl: None) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    _place_log(target, 5, verified_log(5, PHI_1_4.replace("inspected(4)", "inspected(3)")))
    assert AjpfBackend().run(ob, target).status == "stale"


def test_results_parser_search_limits_and_unfinished_runs() -> None:
    limited = verified_log(1, "[] T").replace("constraints=0", "constraints=2")
    assert parse_log(limited).verdict == "incomplete-search"
    cut = verified_log(1, "[] T").split("====================================================== results")[0]
    assert parse_log(cut).verdict == "unfinished"
    crash = verified_log(1, "[] T").replace(
        "no errors detected", "error #1: gov.nasa.jpf.vm.NoUncaughtExceptionsProperty \"java.lang.Null...\"")
    assert parse_log(crash).verdict == "error"
    assert parse_log(verified_log(7, "[] T")).property_name == "7"


def test_imported_evidence_goes_stale_when_the_model_changes(tmp_path: Path, no_mcapl: None) -> None:
    target = make_target(tmp_path)
    ob = _by_id(AjpfBackend().export(target))["Agent.g1.ajpf.p5_i4"]
    _place_log(target, 5, verified_log(5, PHI_1_4))
    ev = AjpfBackend().run(ob, target)
    store = EvidenceStore(tmp_path)
    store.put(ev)
    stored = store.get(ob.id)
    assert stored is not None and store.current_status(stored) == "inconclusive"  # partial coverage
    model = tmp_path / "backends/ajpf/jackal.gwen"
    model.write_text(model.read_text() + "\n// edited\n", encoding="utf-8")
    assert store.current_status(stored) == "stale"
