"""Expected verdicts in the plan are validated at check time, located in plan.yaml."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan, resolve
from rclverify.lang.errors import Diagnostic
from rclverify.lang.typecheck import load

ROOT = Path(__file__).resolve().parents[2]
PLAN = "contracts/plan.yaml"

HEAD = """\
contracts:
  - contracts/remote_inspection.rcl
nodes:
  RadiationSensor:
    evidence:
      - backend: hoare
        program: backends/hoare/radiation_sensor.imp
        expected:
"""


def _ws(tmp_path: Path, expected_lines: str) -> tuple[Path, str]:
    shutil.copytree(ROOT / "contracts", tmp_path / "contracts")
    text = HEAD + expected_lines
    (tmp_path / PLAN).write_text(text, encoding="utf-8")
    return tmp_path, text


def _errors(tmp_path: Path, expected_lines: str) -> tuple[list[Diagnostic], str]:
    root, text = _ws(tmp_path, expected_lines)
    plan = load_plan(root)
    with pytest.raises(PlanError) as info:
        resolve(plan, load([root / c for c in plan.contracts]))
    diags = list(info.value.diagnostics)
    assert all(d.loc.file == PLAN and d.severity == "error" and d.code == "E-plan-expected" for d in diags)
    return diags, text


def _at(text: str, needle: str) -> tuple[int, int]:
    pos = text.index(needle)
    return text.count("\n", 0, pos) + 1, pos - (text.rfind("\n", 0, pos) + 1) + 1


def test_well_formed_expectations_resolve(tmp_path: Path) -> None:
    root, _ = _ws(tmp_path, "          - {guarantee: 1, verdict: discharged, reason: proved by hand}\n"
                            "          - {guarantee: 1, instance: 'i=3', verdict: failed}\n")
    plan = load_plan(root)
    resolve(plan, load([root / c for c in plan.contracts]))  # no error


def test_unknown_verdict_is_located_at_the_verdict(tmp_path: Path) -> None:
    (d,), text = _errors(tmp_path, "          - {guarantee: 1, verdict: proved}\n")
    assert (d.loc.line, d.loc.col) == _at(text, "proved")
    assert "unknown verdict 'proved'" in d.message and "discharged or failed" in d.message


def test_guarantee_the_node_does_not_have(tmp_path: Path) -> None:
    (d,), text = _errors(tmp_path, "          - {guarantee: 7, verdict: failed}\n")
    assert (d.loc.line, d.loc.col) == _at(text, "7")
    assert "node RadiationSensor has 1 guarantee(s); there is no guarantee 7" in d.message


def test_malformed_entries_each_give_one_located_error(tmp_path: Path) -> None:
    diags, text = _errors(tmp_path, "          - failed\n"
                                    "          - {verdict: failed}\n"
                                    "          - {guarantee: first, verdict: failed, why: x}\n"
                                    "          - {guarantee: 1, verdict: failed, instance: 3}\n")
    msgs = {(d.loc.line, d.message.split(": ", 1)[1]) for d in diags}
    line0 = _at(text, "- failed")[0]
    assert (line0, "an expectation must be a mapping {guarantee: N, verdict: discharged|failed, "
                   "instance?: LABEL, reason?: TEXT}") in msgs
    assert (line0 + 1, "an expectation needs 'guarantee' (the guarantee's number, from 1)") in msgs
    assert (line0 + 2, "'guarantee' must be a guarantee number, found 'first'") in msgs
    assert any(line == line0 + 2 and "unknown key 'why'" in m for line, m in msgs)
    assert (line0 + 3, "'instance' must be text, found 3") in msgs
    assert len(diags) == 5
    assert all(d.message.startswith("hoare evidence of RadiationSensor: ") for d in diags)
    # the unknown key is located at the key itself
    why = next(d for d in diags if "unknown key" in d.message)
    assert (why.loc.line, why.loc.col) == _at(text, "why")


def test_expected_that_is_not_a_list(tmp_path: Path) -> None:
    (d,), _ = _errors(tmp_path, "          42\n")
    assert "'expected' must be a list of expectations" in d.message


def test_the_command_line_reports_it_with_a_non_zero_exit(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _, text = _ws(tmp_path, "          - {guarantee: 1, verdict: passed}\n")
    assert main(["compose", "-w", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    line, col = _at(text, "passed")
    assert re.search(rf"^contracts/plan\.yaml:{line}:{col}: error: hoare evidence of RadiationSensor: "
                     r"unknown verdict 'passed'", err, re.M), err
    assert "Traceback" not in err


def test_whole_contract_backends_expect_guarantee_0(tmp_path: Path) -> None:
    from rclverify.report.expected import expected_rows
    head = HEAD.replace("      - backend: hoare\n        program: backends/hoare/radiation_sensor.imp\n",
                        "      - backend: monitors\n        traces: []\n")
    shutil.copytree(ROOT / "contracts", tmp_path / "contracts")
    text = head + "          - {guarantee: 1, verdict: failed}\n"
    (tmp_path / PLAN).write_text(text, encoding="utf-8")
    plan = load_plan(tmp_path)
    with pytest.raises(PlanError) as info:
        resolve(plan, load([tmp_path / c for c in plan.contracts]))
    (d,) = info.value.diagnostics
    assert (d.loc.line, d.loc.col) == _at(text, "1, verdict")
    assert "monitors obligations cover the whole contract of RadiationSensor" in d.message
    assert "write 'guarantee: 0'" in d.message
    # guarantee 0 resolves, and matches the whole-contract obligation in the report
    (tmp_path / PLAN).write_text(head + "          - {guarantee: 0, verdict: failed}\n", encoding="utf-8")
    plan = load_plan(tmp_path)
    resolve(plan, load([tmp_path / c for c in plan.contracts]))
    from _typed_rows import typed_report
    obs = typed_report({"obligations": [{"node": "RadiationSensor", "backend": "monitors", "guarantee": 0,
                                         "status": "failed", "id": "RadiationSensor.g0.monitors.run"}]}).obligations
    (row,) = expected_rows(plan, obs)
    assert row.outcome == "as expected" and row.obligation == "RadiationSensor.g0.monitors.run"
