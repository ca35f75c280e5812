"""The command line: exit codes, located errors on stderr, never a traceback."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.lang.parser import parse_file, parse_text

ROOT = Path(__file__).resolve().parents[2]
CASE_STUDY = ROOT / "contracts" / "remote_inspection.rcl"
BAD = ROOT / "tests" / "data" / "tc_bad.rcl"
LOCATED = re.compile(r"^(?P<file>.+):(?P<line>\d+):(?P<col>\d+): error: (?P<msg>.+)$")


def located_errors(stderr: str) -> list[tuple[str, int, int, str]]:
    out = []
    for line in stderr.splitlines():
        m = LOCATED.match(line)
        assert m, f"not a located diagnostic: {line!r}"
        out.append((m["file"], int(m["line"]), int(m["col"]), m["msg"]))
    return out


def copy_workspace(tmp_path: Path) -> Path:
    ws = tmp_path / "ws"
    shutil.copytree(ROOT / "contracts", ws / "contracts")
    # the plan's experiment and review entries are checked with the plan
    for rel in ("backends/experiment", "backends/review"):
        shutil.copytree(ROOT / rel, ws / rel)
    return ws


# ---------------------------------------------------------------------------
# check / fmt / latex
# ---------------------------------------------------------------------------

def test_check_case_study_prints_lint_warnings(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(CASE_STUDY)]) == 0
    out, err = capsys.readouterr()
    assert err == ""
    lines = out.splitlines()
    warnings = [l for l in lines if ": warning: " in l]
    assert warnings and all(l.startswith(f"{CASE_STUDY}:") for l in warnings)
    # Guarantee 3 of the Agent binds x' and y' and never uses them (line 72 of the case study).
    assert any("bound variable x' of 'forall' is never used" in l for l in warnings)
    assert lines[-1] == f"1 file(s): 0 errors, {len(warnings)} warning(s)"


def test_check_bad_file_reports_located_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(BAD)]) == 1
    out, err = capsys.readouterr()
    assert out == "" and "Traceback" not in err
    errs = located_errors(err)
    text = BAD.read_text(encoding="utf-8").splitlines()
    assert [(f, l, c) for f, l, c, _ in errs] == [
        (str(BAD), 9, text[8].index("in.rr") + 1),
        (str(BAD), 10, text[9].index("in.ok") + 1),
    ]
    assert "did you mean 'r'" in errs[0][3] and "'<' needs numbers, found BOOL" in errs[1][3]


def test_check_syntax_error_and_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "syn.rcl"
    bad.write_text("node N { inputs(x : REAL) outputs(y : REAL)\n  guarantee(out.y == ) }\n", encoding="utf-8")
    assert main(["check", str(bad)]) == 1
    ((f, line, col, msg),) = located_errors(capsys.readouterr().err)
    assert (f, line, col) == (str(bad), 2, 22) and msg.startswith("unexpected ')'")
    missing = tmp_path / "missing.rcl"
    assert main(["check", str(missing)]) == 1
    ((f, line, col, msg),) = located_errors(capsys.readouterr().err)
    assert (f, line, col) == (str(missing), 1, 1) and "cannot read RCL file" in msg


def test_fmt_output_reparses_to_the_same_ast(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fmt", str(CASE_STUDY)]) == 0
    out = capsys.readouterr().out
    assert parse_text(out, "formatted.rcl") == parse_file(CASE_STUDY)
    assert main(["fmt", str(BAD)]) == 0  # fmt does not type-check
    assert parse_text(capsys.readouterr().out) == parse_file(BAD)


def test_latex(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["latex", str(CASE_STUDY)]) == 0
    out = capsys.readouterr().out
    assert "\\forall" in out and "\\exists!" in out
    assert "\\begin{document}" in out and "\\end{document}" in out
    assert main(["latex", str(BAD)]) == 1  # latex type-checks first
    assert located_errors(capsys.readouterr().err)


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main([])
    assert info.value.code == 2
    with pytest.raises(SystemExit) as info:
        main(["frobnicate"])
    assert info.value.code == 2
    capsys.readouterr()


# ---------------------------------------------------------------------------
# compose / refines
# ---------------------------------------------------------------------------

def test_compose_discharges_the_agent_side_condition(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = copy_workspace(tmp_path)
    assert main(["compose", "-w", str(ws)]) == 0
    out = capsys.readouterr().out
    # each discharged side condition says which variant discharged it (the paper's rules use guarantees only)
    assert re.search(r"side condition Agent\.sc1 \[discharged\] \((as written|with producers' assumptions)\): "
                     r"in\.radiationStatus in \{red, orange, green\}  \(contracts/remote_inspection\.rcl:\d+:\d+\)", out)
    assert "side condition Navigation.sc1 [discharged]" in out
    assert "Localisation: rules (source node)" in out
    assert (ws / "artifacts" / "calculus" / "Agent.sc1.smt2").is_file()


def test_compose_with_a_bad_plan_is_a_located_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = copy_workspace(tmp_path)
    plan = ws / "contracts" / "plan.yaml"
    plan.write_text("contracts:\n  - contracts/remote_inspection.rcl\nrequirements:\n"
                    "  - id: R\n    text: t\n    supported_by:\n      - {node: Nobody, guarantees: [1]}\n",
                    encoding="utf-8")
    assert main(["compose", "-w", str(ws)]) == 1
    out, err = capsys.readouterr()
    ((f, line, col, msg),) = located_errors(err)
    assert (f, line, col) == ("contracts/plan.yaml", 7, 9) and "no node named 'Nobody'" in msg


def test_compose_on_a_missing_workspace_is_a_located_error(tmp_path: Path,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["compose", "-w", str(tmp_path / "nowhere")]) == 1
    assert located_errors(capsys.readouterr().err)


def test_refines_is_wired(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(["refines", "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "original" in out and "replacement" in out
    spec = f"{CASE_STUDY}:RadiationSensor"
    assert main(["refines", spec, spec]) == 0
    assert "verdict: yes" in capsys.readouterr().out


# ---------------------------------------------------------------------------
# The console script as a user runs it
# ---------------------------------------------------------------------------

def test_console_script_prints_no_traceback() -> None:
    proc = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "check", str(BAD)],
                          capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert proc.returncode == 1
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    errs = located_errors(proc.stderr)
    assert [(l, c) for _, l, c, _ in errs] == [(9, 16), (10, 14)]


def test_graph_writes_dot_and_svg(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import shutil as sh
    ws = tmp_path / "ws"
    sh.copytree(ROOT / "contracts", ws / "contracts")
    sh.copytree(ROOT / "backends", ws / "backends")
    out = tmp_path / "model.dot"
    assert main(["graph", "-w", str(ws), "-o", str(out)]) == 0
    dot = out.read_text()
    assert dot.lstrip().startswith(("digraph", "//", "/*")) and "Localisation" in dot and "RadiationSensor" in dot
    if sh.which("dot"):
        assert "<svg" in out.with_suffix(".svg").read_text()


def test_strict_gate_counts_side_conditions_not_only_evidence(tmp_path: Path) -> None:
    """No obligation at all, but a refuted side condition: the report must not pass --strict."""
    import json
    (tmp_path / "contracts").mkdir()
    rover = (ROOT / "tests" / "data" / "rover_navigation.rcl").read_text()
    (tmp_path / "contracts" / "rover.rcl").write_text(rover.replace("out.dest_plan <= 20", "out.dest_plan <= 25"))
    (tmp_path / "contracts" / "plan.yaml").write_text("contracts: [contracts/rover.rcl]\n")
    assert main(["compose", "-w", str(tmp_path)]) == 1  # Interface.sc1 is refuted
    assert main(["report", "-w", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "reports" / "assurance.json").read_text())
    assert report["obligations"] == [] and report["meta"]["strict_ok"] is False


def test_verify_with_a_missing_workspace_or_plan_is_one_located_error(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """Not doit's sqlite3.OperationalError or DependencyError: the message compose gives, exit 1."""
    assert main(["verify", "-w", str(tmp_path / "missing")]) == 1
    err = capsys.readouterr().err
    assert err == f"{tmp_path / 'missing'}: error: no such workspace directory\n"
    ws = copy_workspace(tmp_path / "ws")
    assert main(["verify", "-w", str(ws), "--plan", "contracts/missing.yaml"]) == 1
    assert capsys.readouterr().err.startswith("contracts/missing.yaml:1:1: error: cannot read the verification plan")
    assert not (tmp_path / "missing").exists()
