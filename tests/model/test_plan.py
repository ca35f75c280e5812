"""Verification plan: loading, schema errors and references into the contracts, all located."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rclverify.backends import KNOWN
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import Plan, load_plan, resolve
from rclverify.lang.errors import Diagnostic
from rclverify.lang.typecheck import load

ROOT = Path(__file__).resolve().parents[2]
PLAN = "contracts/plan.yaml"

# A small plan over the case study.  Line numbers matter to the tests below.
BASE = """\
name: test plan
contracts:
  - contracts/remote_inspection.rcl
requirements:
  - id: R1
    text: The robot inspects the waypoints.
    supported_by:
      - {node: Agent, guarantees: [1, 2]}
      - {node: RadiationSensor, guarantees: [1]}
connections: []
environment:
  Agent:
    facts:
      - "forall(x, y in REAL | in.wayP(x, y) <= 12)"
    instances: [0, 12]
  RadiationSensor:
    - "in.r <= 1000"
nodes:
  Agent:
    evidence:
      - backend: dafny
        implementation: backends/dafny/agent.dfy
  RadiationSensor:
    evidence:
      - backend: hoare
        program: backends/hoare/radiation_sensor.imp
"""


def workspace(tmp_path: Path, plan_text: str) -> Path:
    shutil.copytree(ROOT / "contracts", tmp_path / "contracts")
    (tmp_path / PLAN).write_text(plan_text, encoding="utf-8")
    return tmp_path


def where(text: str, needle: str, occurrence: int = 1) -> tuple[int, int]:
    pos = -1
    for _ in range(occurrence):
        pos = text.index(needle, pos + 1)
    return text.count("\n", 0, pos) + 1, pos - (text.rfind("\n", 0, pos) + 1) + 1


def load_errors(tmp_path: Path, text: str) -> list[Diagnostic]:
    root = workspace(tmp_path, text)
    with pytest.raises(PlanError) as info:
        load_plan(root)
    assert all(d.loc.file == PLAN and d.severity == "error" for d in info.value.diagnostics)
    return list(info.value.diagnostics)


def resolve_errors(tmp_path: Path, text: str) -> list[Diagnostic]:
    root = workspace(tmp_path, text)
    plan = load_plan(root)
    checked = load([root / c for c in plan.contracts])
    with pytest.raises(PlanError) as info:
        resolve(plan, checked)
    return list(info.value.diagnostics)


def at(d: object) -> tuple[int, int]:
    loc = d.loc  # type: ignore[attr-defined]
    return loc.line, loc.col


# ---------------------------------------------------------------------------
# The workspace's own plan
# ---------------------------------------------------------------------------

def test_the_workspace_plan_loads_and_resolves() -> None:
    plan = load_plan(ROOT)
    assert plan.file == PLAN and plan.root == ROOT
    assert plan.contracts == ("contracts/remote_inspection.rcl",)
    assert [r.id for r in plan.requirements] == ["REQ1", "REQ2", "REQ3", "REQ4"]
    assert all(r.text and r.support for r in plan.requirements)
    text = (ROOT / PLAN).read_text(encoding="utf-8")
    fact = plan.facts["Agent"][0]
    assert fact.node == "Agent" and fact.loc.file == PLAN
    line, col = where(text, fact.text)
    assert (fact.loc.line, fact.loc.col) == (line, col)  # the formula itself, inside the quotes
    assert plan.instances["Agent"] == (0, 12)
    for node, entries in plan.evidence.items():
        for k, e in enumerate(entries):
            assert e.node == node and e.index == k and e.backend in KNOWN and e.config["backend"] == e.backend
    checked = load([ROOT / c for c in plan.contracts])
    resolve(plan, checked)  # no error
    assert set(plan.evidence) <= set(checked.nodes)


def test_a_small_plan_loads(tmp_path: Path) -> None:
    plan = load_plan(workspace(tmp_path, BASE))
    assert isinstance(plan, Plan) and plan.name == "test plan"
    (req,) = plan.requirements
    assert req.id == "R1" and req.text == "The robot inspects the waypoints."
    assert [(s.node, s.guarantees) for s in req.support] == [("Agent", (1, 2)), ("RadiationSensor", (1,))]
    assert at(req.support[1]) == (9, 9)
    assert plan.connections == ()
    assert [f.text for f in plan.facts["RadiationSensor"]] == ["in.r <= 1000"]
    assert plan.facts["RadiationSensor"][0].loc.line == 17
    assert plan.instances == {"Agent": (0, 12)}
    assert plan.evidence["Agent"][0].config["implementation"] == "backends/dafny/agent.dfy"
    resolve(plan, load([tmp_path / c for c in plan.contracts]))


def test_explicit_connections_are_read(tmp_path: Path) -> None:
    text = BASE.replace("connections: []", "connections:\n  - {from: Agent.command, to: Navigation.command}")
    plan = load_plan(workspace(tmp_path, text))
    (c,) = plan.connections
    assert (c.from_node, c.from_var, c.to_node, c.to_var) == ("Agent", "command", "Navigation", "command")
    assert (c.loc.line, c.loc.col) == where(text, "{from: Agent")
    resolve(plan, load([tmp_path / x for x in plan.contracts]))


# ---------------------------------------------------------------------------
# Read and schema errors (load_plan)
# ---------------------------------------------------------------------------

def test_missing_plan_file(tmp_path: Path) -> None:
    with pytest.raises(PlanError) as info:
        load_plan(tmp_path)
    (d,) = info.value.diagnostics
    assert str(d).startswith("contracts/plan.yaml:1:1: error: cannot read the verification plan")


def test_missing_contracts_key(tmp_path: Path) -> None:
    text = BASE.replace("contracts:\n  - contracts/remote_inspection.rcl\n", "")
    (d,) = load_errors(tmp_path, text)
    assert "plan: 'contracts' is a required key and is missing" in d.message and at(d) == (1, 1)


def test_unknown_top_level_key_is_named(tmp_path: Path) -> None:
    (d,) = load_errors(tmp_path, BASE.replace("name: test plan", "nmae: test plan"))
    assert "plan: unknown key 'nmae' (did you mean 'name'?); the known keys are: " in d.message and at(d) == (1, 1)


def test_unknown_top_level_key_is_located_at_the_key(tmp_path: Path) -> None:
    text = BASE + "extra_key: 1\n"
    (d,) = load_errors(tmp_path, text)
    assert "plan: unknown key 'extra_key'; the known keys are: acknowledged, connections, contracts," in d.message
    assert d.loc.line == where(text, "extra_key")[0]


def test_unknown_nested_key(tmp_path: Path) -> None:
    text = BASE.replace("{node: RadiationSensor, guarantees: [1]}", "{node: RadiationSensor, guarantees: [1], why: x}")
    (d,) = load_errors(tmp_path, text)
    assert "requirements.0.supported_by.1: unknown key 'why'; the known keys are: guarantees, node" in d.message
    assert at(d) == where(text, "why: x")  # located at the offending key


def test_an_unknown_key_in_place_of_a_required_one_is_one_line_naming_both(tmp_path: Path) -> None:
    text = BASE.replace("contracts:\n  - contracts/remote_inspection.rcl\n", "clauses:\n  - contracts/remote_inspection.rcl\n")
    (d,) = load_errors(tmp_path, text)  # not a second line for the missing 'contracts'
    assert d.message.startswith("plan: unknown key 'clauses' (did you mean 'contracts'? it is required and missing); "
                                "the known keys are: "), d.message
    assert "type" not in d.message and at(d) == where(text, "clauses:")


@pytest.mark.parametrize("key", ["clauses", "Agent"])
def test_a_key_under_nodes_that_names_no_node_is_an_unknown_key(key: str, tmp_path: Path) -> None:
    # a node's key indented one level too high reads as a node named 'clauses' whose entry is a list
    text = BASE.replace("nodes:\n  Agent:\n", f"nodes:\n  {key}: [1]\n  Agent:\n" if key != "Agent" else
                        "nodes:\n  Agent: [1]\n  Agents:\n")
    (d,) = load_errors(tmp_path, text)
    if key == "Agent":  # the control: a node's entry of the wrong type says so
        assert d.message == "nodes.Agent: [1] is not of type 'object'", d.message
        return
    assert d.message.startswith("nodes.clauses: unknown key 'clauses': no node of the contracts is named so; "), d.message
    assert "the nodes are: Localisation, Navigation, Agent, RadiationSensor" in d.message
    assert at(d) == where(text, "clauses: [1]") and "type" not in d.message


def test_requirement_without_text(tmp_path: Path) -> None:
    text = BASE.replace("    text: The robot inspects the waypoints.\n", "")
    (d,) = load_errors(tmp_path, text)
    assert "requirements.0: 'text' is a required key and is missing" in d.message
    assert at(d) == where(text, "id: R1")


def test_wrong_value_types_are_located(tmp_path: Path) -> None:
    text = BASE.replace("guarantees: [1, 2]", "guarantees: [0, two]")
    diags = load_errors(tmp_path, text)
    assert len(diags) == 2
    line = where(text, "[0, two]")[0]
    assert all(d.loc.line == line for d in diags)
    assert any("0 is less than the minimum of 1" in d.message for d in diags)
    assert any("'two' is not of type 'integer'" in d.message for d in diags)


def test_nonexistent_contract_file(tmp_path: Path) -> None:
    text = BASE.replace("contracts/remote_inspection.rcl", "contracts/nowhere.rcl")
    (d,) = load_errors(tmp_path, text)
    assert d.code == "E-io" and at(d) == where(text, "contracts/nowhere.rcl")
    assert d.message == "contract file 'contracts/nowhere.rcl' does not exist"


def test_tab_in_yaml(tmp_path: Path) -> None:
    text = BASE.replace("  - id: R1", "\t- id: R1")
    (d,) = load_errors(tmp_path, text)
    assert d.code == "E-yaml" and d.loc.line == where(text, "\t- id")[0]
    assert d.message.startswith("invalid YAML:") and "'\\t'" in d.message


def test_bad_indentation_in_yaml(tmp_path: Path) -> None:
    text = BASE.replace("    text: The robot", "   text: The robot")
    (d,) = load_errors(tmp_path, text)
    assert d.code == "E-yaml" and d.loc.line == where(text, "   text:")[0]


def test_plan_that_is_not_a_mapping(tmp_path: Path) -> None:
    (d,) = load_errors(tmp_path, "- contracts/remote_inspection.rcl\n")
    assert at(d) == (1, 1) and "must be a mapping" in d.message


def test_fact_with_an_rcl_syntax_error_is_located_in_the_plan_line(tmp_path: Path) -> None:
    text = BASE.replace('"in.r <= 1000"', '"in.r <= )"')
    (d,) = load_errors(tmp_path, text)
    assert d.code == "E-syntax" and d.message.startswith("unexpected ')'")
    line, col = where(text, '<= )"')
    assert at(d) == (line, col + 3)


def test_fact_syntax_error_in_an_unquoted_scalar(tmp_path: Path) -> None:
    text = BASE.replace('"in.r <= 1000"', "in.r <= * 3")
    (d,) = load_errors(tmp_path, text)
    assert d.code == "E-syntax" and at(d) == where(text, "* 3")


def test_fact_syntax_error_in_a_block_scalar(tmp_path: Path) -> None:
    text = BASE.replace('    - "in.r <= 1000"', "    - >-\n      in.r <=\n        )")
    (d,) = load_errors(tmp_path, text)
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.strip() == ")")
    assert d.code == "E-syntax" and at(d) == (k + 1, lines[k].index(")") + 1)


# ---------------------------------------------------------------------------
# References into the contracts (resolve)
# ---------------------------------------------------------------------------

def test_unknown_node_in_supported_by(tmp_path: Path) -> None:
    text = BASE.replace("{node: RadiationSensor, guarantees: [1]}", "{node: RadSensor, guarantees: [1]}")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "{node: RadSensor")
    assert d.message == ("no node named 'RadSensor' in the contracts; nodes are: "
                         "Localisation, Navigation, Agent, RadiationSensor")


def test_guarantee_index_out_of_range(tmp_path: Path) -> None:
    text = BASE.replace("guarantees: [1, 2]", "guarantees: [1, 4]")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "{node: Agent")
    assert d.message == "R1: node Agent has 3 guarantee(s); there is no guarantee 4"


def test_connection_to_a_missing_input(tmp_path: Path) -> None:
    text = BASE.replace("connections: []", "connections:\n  - {from: Agent.command, to: Navigation.cmd}")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "{from: Agent")
    assert d.message == "Navigation has no input 'cmd'"


def test_connection_between_different_types(tmp_path: Path) -> None:
    text = BASE.replace("connections: []", "connections:\n  - {from: Navigation.at, to: Agent.wayP}")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "{from: Navigation")
    assert "Navigation.at : REAL x REAL --> BOOL" in d.message and "Agent.wayP : REAL x REAL --> NATURAL" in d.message


def test_unknown_backend_lists_the_known_ones(tmp_path: Path) -> None:
    text = BASE.replace("backend: hoare", "backend: hoar")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "hoar\n")
    assert d.message.startswith("unknown backend 'hoar'; known backends: ")
    assert all(k in d.message for k in KNOWN)


def test_misspelt_entry_key_is_located_with_the_closest_key(tmp_path: Path) -> None:
    text = BASE.replace("        implementation: backends/dafny/agent.dfy",
                        "        implementation: backends/dafny/agent.dfy\n        time_limt: 5")
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, "time_limt")
    assert d.message == "unknown key 'time_limt' in a dafny evidence entry; did you mean 'time_limit'?"


@pytest.mark.parametrize("backend", sorted(KNOWN))
def test_every_backend_rejects_an_unknown_key_and_accepts_expected(backend: str) -> None:
    from rclverify.backends.keys import allowed_keys, unknown_key_messages
    assert "expected" in allowed_keys(backend)
    assert unknown_key_messages(backend, {"backend": backend, "expected": []}) == []
    ((key, msg),) = unknown_key_messages(backend, {"backend": backend, "frobnicate": 1})
    assert key == "frobnicate" and msg.startswith(f"unknown key 'frobnicate' in a {backend} evidence entry; ")


def test_evidence_for_an_unknown_node(tmp_path: Path) -> None:
    text = BASE.replace("  RadiationSensor:\n    evidence:", "  RadiationSensr:\n    evidence:")
    (d,) = resolve_errors(tmp_path, text)
    assert "no node named 'RadiationSensr'" in d.message and d.loc.line == where(text, "- backend: hoare")[0]


def test_fact_that_is_not_a_formula(tmp_path: Path) -> None:
    text = BASE.replace('"in.r <= 1000"', '"in.r + 1000"')
    (d,) = resolve_errors(tmp_path, text)
    assert at(d) == where(text, 'in.r + 1000')
    assert d.message == "an environment fact must be a formula, found REAL"


def test_fact_with_an_unknown_name(tmp_path: Path) -> None:
    text = BASE.replace("in.wayP(x, y) <= 12", "in.wayPt(x, y) <= 12")
    (d,) = resolve_errors(tmp_path, text)
    assert d.code == "E-name" and d.loc.file == PLAN and at(d) == where(text, "in.wayPt")
    assert "no input named 'wayPt'" in d.message and "did you mean 'wayP'" in d.message


def test_facts_for_an_unknown_node(tmp_path: Path) -> None:
    text = BASE.replace("  RadiationSensor:\n    - ", "  Radiation:\n    - ")
    (d,) = resolve_errors(tmp_path, text)
    assert "no node named 'Radiation'" in d.message and at(d) == where(text, "in.r <= 1000")


def test_resolve_reports_every_problem(tmp_path: Path) -> None:
    text = (BASE.replace("guarantees: [1, 2]", "guarantees: [9]")
            .replace("backend: hoare", "backend: nope")
            .replace('"in.r <= 1000"', '"in.q <= 1000"'))
    diags = resolve_errors(tmp_path, text)
    assert len(diags) == 3
    assert all(d.loc.file == PLAN for d in diags)
