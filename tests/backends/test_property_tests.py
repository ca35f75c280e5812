"""Tests of the property_tests backend and of the Z3 check on concrete values
(rclverify.semantics.concrete): real Hypothesis runs on small workspaces."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from rclverify.backends import get_backend
from rclverify.backends.property_tests.backend import PropertyTestsBackend
from rclverify.records.records import Evidence
from rclverify.semantics.concrete import check_concrete
from rclverify.app.pipeline import Workspace
from rclverify.model.plan.errors import PlanError
from rclverify.lang.typecheck import load
from rclverify.semantics.values import FiniteFunction, Term

REPO = Path(__file__).resolve().parents[2]
RCL = "contracts/remote_inspection.rcl"

GOOD = '''
from rclverify.semantics.values import FiniteFunction

def sensor(r, command):
    status = "green" if r < 120 else "orange" if r < 250 else "red"
    table = {(command.args[0],): True} if command.name == "inspect" else {}
    return {"radiationStatus": status, "inspected": FiniteFunction(table, False, 1)}
'''
OFF_BY_ONE = GOOD.replace("r < 120", "r <= 120")
OUT_OF_TYPE = GOOD.replace('"red"', '"yellow"')
RAISES = GOOD.replace("    status =", "    if r > 1000: raise ValueError('too hot')\n    status =")
STATEFUL = '''
from rclverify.semantics.values import FiniteFunction

class Sensor:
    """Remembers every inspected waypoint."""
    def __init__(self):
        self.done = {}

    def step(self, r, command):
        if command.name == "inspect":
            self.done[(command.args[0],)] = True
        status = "green" if r < 120 else "orange" if r < 250 else "red"
        return {"radiationStatus": status, "inspected": FiniteFunction(dict(self.done), False, 1)}
'''


def workspace(tmp: Path, impl: str, extra: str = "", rcl: str | None = None, node: str = "RadiationSensor") -> Path:
    (tmp / "contracts").mkdir(parents=True)
    if rcl is None:
        shutil.copy(REPO / RCL, tmp / RCL)
    else:
        (tmp / RCL).write_text(rcl)
    (tmp / "impl.py").write_text(impl)
    attr = "Sensor" if "class Sensor" in impl else "sensor"
    (tmp / "contracts/plan.yaml").write_text(
        f"contracts: [{RCL}]\nnodes:\n  {node}:\n    evidence:\n      - backend: property_tests\n"
        f"        implementation: impl.py:{attr}\n        max_examples: 100\n{extra}")
    return tmp


def run(root: Path, node: str = "RadiationSensor", guarantee: int = 1) -> Evidence:
    ws = Workspace(root)
    target = ws.target(node, 0)
    backend = PropertyTestsBackend()
    obligations = backend.export(target)
    return backend.run(obligations[guarantee - 1], target)


# -- the Z3 check on concrete values ------------------------------------------------------------

@pytest.fixture(scope="module")
def checked() -> Any:
    return load([REPO / RCL])


def test_check_concrete_radiation_sensor(checked: Any) -> None:
    node = checked.nodes["RadiationSensor"]
    g = node.node.guarantees[0].formula
    values = {"in.r": 130.0, "in.command": Term("inspect", (3,)), "out.radiationStatus": "orange",
              "out.inspected": FiniteFunction({(3,): True}, False, 1)}
    assert check_concrete(g, checked, node, values) == (True, "")
    assert check_concrete(g, checked, node, {**values, "out.radiationStatus": "green"}) == (False, "")
    assert check_concrete(g, checked, node, {**values, "out.inspected": FiniteFunction({}, False, 1)}) == (False, "")
    with pytest.raises(KeyError, match="out.radiationStatus"):
        check_concrete(g, checked, node, {k: v for k, v in values.items() if k != "out.radiationStatus"})


def test_check_concrete_quantifies_over_function_tables(checked: Any) -> None:
    node = checked.nodes["Agent"]
    wayp = FiniteFunction({(0.0, 0.0): 0, (1.0, 2.0): 1}, 5, 2)
    values = {"in.wayP": wayp, "in.at": FiniteFunction({(1.0, 2.0): True}, False, 2), "in.radiationStatus": "green",
              "in.inspected": FiniteFunction({(1,): True}, False, 1)}
    g1 = node.node.guarantees[0].formula
    # at waypoint 1, inspected, no waypoint 2: guarantee 1 asks for a move to waypoint 0 at (0, 0)
    assert check_concrete(g1, checked, node, {**values, "out.command": Term("move", (0.0, 0.0))})[0] is True
    assert check_concrete(g1, checked, node, {**values, "out.command": Term("move", (1.0, 2.0))})[0] is False


# -- the backend ---------------------------------------------------------------------------------

def test_registered() -> None:
    assert isinstance(get_backend("property_tests"), PropertyTestsBackend)


def test_correct_implementation_discharged(tmp_path: Path) -> None:
    ev = run(workspace(tmp_path, GOOD))
    assert ev.status == "discharged", ev.explanation
    assert ev.kind == "testing" and ev.tool == "hypothesis" and "z3" in ev.tool_version
    ex = ev.details["examples"]
    assert ex["valid"] == 100 and ex["failures"] == 0 and ex["inconclusive"] == 0
    assert "impl.py" in ev.input_hashes
    cov = ev.details["coverage"]  # r is bounded below only; a command is a term: not measured
    assert cov["in.r"]["range"] == "[0, inf]" and cov["in.r"]["fraction"] is None and ".." in cov["in.r"]["drawn"]
    assert cov["in.command"]["fraction"] is None and "not measured" in cov["in.command"]["range"]


def test_the_coverage_of_a_bounded_range_is_the_buckets_the_examples_hit(tmp_path: Path) -> None:
    from _typed_rows import complete
    from rclverify.records.evidence_rows import EvidenceRow
    from rclverify.report.argument.strength import evidence_strength
    ev = run(workspace(tmp_path, GOOD, extra="        bounds: {in.r: [0, 500]}\n"))
    c = ev.details["coverage"]["in.r"]
    lo, hi = (float(x) for x in c["drawn"].split(".."))
    assert c["range"] == "[0, 500]" and c["buckets"] == 10 and 0 <= lo <= hi <= 500
    assert c["fraction"] == c["covered"] / 10 and 1 <= c["covered"] <= 10
    row = {"backend": "property_tests", "status": ev.status, "examples": {**ev.details["examples"],
                                                                         "coverage": ev.details["coverage"]}}
    # r's assumption bounds it below only: the fraction is of the plan's [0, 500], and the detail says so
    assert (f"in.r {c['fraction']:.0%} of [0, 500] (drawn {c['drawn']}, the plan's bounds; the assumption admits "
            "[0, inf])") in str(evidence_strength(EvidenceRow.of(complete(EvidenceRow, row))).detail)


def test_off_by_one_threshold_caught_with_shrunk_counterexample(tmp_path: Path) -> None:
    ev = run(workspace(tmp_path, OFF_BY_ONE))
    assert ev.status == "failed"
    cex = ev.counterexample or {}
    assert cex["in.r"] == "120" or cex["in.r"] == "120.0"
    assert cex["out.radiationStatus"] == "green"
    assert cex["guarantee"] == "RadiationSensor guarantee 1"
    assert cex["source"].startswith("contracts/remote_inspection.rcl:")
    assert "test_guarantee_1" in cex["replay"]


def test_out_of_type_output_named(tmp_path: Path) -> None:
    ev = run(workspace(tmp_path, OUT_OF_TYPE, extra="        bounds: {in.r: [0, 100000]}\n"))
    assert ev.status == "failed"
    assert "output out.radiationStatus is not a value of its type" in ev.explanation
    assert "'yellow'" in ev.explanation


def test_raising_implementation_fails(tmp_path: Path) -> None:
    ev = run(workspace(tmp_path, RAISES))
    assert ev.status == "failed"
    assert "raised ValueError: too hot" in ev.explanation


def test_stateful_implementation_checked_step_by_step(tmp_path: Path) -> None:
    ev = run(workspace(tmp_path, STATEFUL))
    assert ev.status == "discharged", ev.explanation
    assert ev.details["examples"]["steps_checked"] > ev.details["examples"]["valid"]


def test_starved_filter_gives_health_message(tmp_path: Path) -> None:
    rcl = ("context { K : {a} ; }\nnode Sq {\n  inputs( x : REAL )\n  outputs( y : REAL )\n"
           "  assume( in.x * in.x == 2 )\n  guarantee( out.y == in.x )\n}\n")
    impl = "def sensor(x):\n    return {'y': x}\n"
    ev = run(workspace(tmp_path, impl, rcl=rcl, node="Sq"), node="Sq")
    assert ev.status == "error"
    assert "in.x * in.x == 2" in ev.explanation and "contracts/remote_inspection.rcl:5:" in ev.explanation
    assert "filtering cannot find inputs" in ev.explanation
    assert ev.details["examples"]["rejected"] > 0 and ev.details["examples"]["valid"] == 0


def test_same_seed_same_evidence(tmp_path: Path) -> None:
    root = workspace(tmp_path, OFF_BY_ONE)
    a, b = run(root).to_json(), run(root).to_json()
    for k in ("started", "duration_s"):
        a.pop(k), b.pop(k)
    assert a == b


LOGGING = GOOD.replace("def sensor(r, command):\n", """def sensor(r, command):
    import pathlib
    with open(pathlib.Path(__file__).parent / "drawn.log", "a") as log:
        log.write(repr((r, command)) + "\\n")
""")


def test_same_seed_same_examples_whatever_the_process_imported_before(tmp_path: Path) -> None:
    """Hypothesis mixes constants from the source of the process's local modules into its draws;
    which modules a doit worker has loaded depends on what it ran before, so the examples did too.
    A local module with new numeric constants imported between two runs changes no example."""
    root = workspace(tmp_path / "ws", LOGGING)
    assert run(root).status == "discharged"
    first = (root / "drawn.log").read_text()
    (root / "drawn.log").unlink()
    mod = tmp_path / "mods" / "noise_constants_module.py"
    mod.parent.mkdir()
    mod.write_text("".join(f"C{k} = {v}\n" for k, v in enumerate((119.5, 121.25, 249.75, 251.5, 7.25e3, 1e-300))))
    sys.path.insert(0, str(mod.parent))
    try:
        import noise_constants_module  # noqa: F401  (a local module, new to the process)
        assert run(root).status == "discharged"
    finally:
        sys.path.remove(str(mod.parent))
        sys.modules.pop("noise_constants_module", None)
    assert (root / "drawn.log").read_text() == first


def test_bad_entry_is_a_located_plan_error(tmp_path: Path) -> None:
    root = workspace(tmp_path, GOOD)
    plan = (root / "contracts/plan.yaml").read_text().replace("impl.py:sensor", "impl.py:nosuch")
    (root / "contracts/plan.yaml").write_text(plan)
    with pytest.raises(PlanError, match=r"contracts/plan.yaml:\d+:\d+: error: impl.py has no callable 'nosuch'"):
        PropertyTestsBackend().export(Workspace(root).target("RadiationSensor", 0))


@pytest.mark.parametrize("impl,status,rc", [(GOOD, "discharged", 0), (OFF_BY_ONE, "failed", 1)],
                         ids=["correct", "off_by_one"])
def test_written_pytest_file_agrees_with_backend(tmp_path: Path, impl: str, status: str, rc: int) -> None:
    root = workspace(tmp_path, impl)
    ev = run(root)
    assert ev.status == status
    (artifact,) = ev.artifacts
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", artifact],
                          cwd=root, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == rc, proc.stdout + proc.stderr
    if rc:
        assert "in.r = 120" in proc.stdout


def test_check_concrete_rejects_unknown_name(checked: Any) -> None:
    node = checked.nodes["RadiationSensor"]
    with pytest.raises(KeyError, match="no out.nope"):
        check_concrete(node.node.guarantees[0].formula, checked, node, {"out.nope": 1})


def test_z3_unknown_is_inconclusive_never_passed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.backends.property_tests import harness
    from rclverify.semantics.floatsem import Judgement

    def unknown_on_guarantee(formula: Any, checked: Any, node: Any, values: Any, *a: Any, **kw: Any) -> Any:
        assert any(k.startswith("out.") for k in values)  # judge decides the guarantee checks only
        return Judgement(None, "", "timeout")

    monkeypatch.setattr(harness, "judge", unknown_on_guarantee)
    ev = run(workspace(tmp_path, GOOD))
    assert ev.status == "inconclusive"
    assert ev.details["examples"]["inconclusive"] == 100 and ev.details["unknown_reasons"] == ["timeout"]
    assert "Z3 answered unknown on 100 example(s)" in ev.explanation


# -- one evaluator: direct evaluation first, Z3 only where it cannot decide -------------------------

def _count_z3(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    from rclverify.backends.property_tests import harness
    from rclverify.semantics import decide as decide_module
    calls: list[str] = []
    for module in (decide_module, harness):
        real = module.check_concrete

        def counting(*args: Any, _real: Any = real, _where: str = module.__name__, **kw: Any) -> Any:
            calls.append(_where)
            return _real(*args, **kw)
        monkeypatch.setattr(module, "check_concrete", counting)
    return calls


def test_examples_are_checked_by_direct_evaluation(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The Radiation Sensor's quantified guarantee is decided without Z3 on every example."""
    calls = _count_z3(monkeypatch)
    ev = run(workspace(tmp_path, GOOD))
    assert ev.status == "discharged" and ev.details["examples"]["valid"] == 100
    assert calls == []


def test_counterexample_is_confirmed_by_z3(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A failed run asks Z3 once more, on the reported counterexample only."""
    calls = _count_z3(monkeypatch)
    ev = run(workspace(tmp_path, OFF_BY_ONE))
    assert ev.status == "failed"
    assert calls == ["rclverify.backends.property_tests.harness"]


def test_engines_disagreeing_on_a_counterexample_is_an_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Should Z3 not confirm the counterexample direct evaluation found, the evidence says so: error, not failed."""
    from rclverify.backends.property_tests import harness
    monkeypatch.setattr(harness, "check_concrete", lambda *a, **k: (True, ""))
    ev = run(workspace(tmp_path, OFF_BY_ONE))
    assert ev.status == "error"
    assert "direct evaluation and Z3 disagree" in ev.explanation


# -- numbers as the implementation computes them (issue 40) ----------------------------------------

RANGER = """
node Ranger {
  inputs( r : REAL )
  outputs( d : REAL )
  assume( 0 <= in.r and in.r <= 30 )
  guarantee( out.d == 1000 * in.r )
}
"""


@pytest.mark.parametrize("impl,status", [("def ranger(r):\n    return {'d': r * 1000.0}\n", "discharged"),
                                         ("def ranger(r):\n    return {'d': r * 1000.0 + 1.0}\n", "failed")],
                         ids=["double", "off_by_one_mm"])
def test_a_guarantee_that_holds_in_double_is_no_violation(tmp_path: Path, impl: str, status: str) -> None:
    """``r * 1000.0`` in Python floats is, for most drawn r, not the exact rational
    ``1000 * r`` (1.2 * 1000.0 == 1200.0 while 1.2 is 1.1999999999999999555...): judged exactly,
    a correct implementation failed (the warehouse example's LidarDriver).  Judged as the
    implementation computes, as the monitors judge a recorded run, it is discharged with the count
    said; an implementation one millimetre off still fails, false in every semantics."""
    root = workspace(tmp_path, impl.replace("ranger", "sensor"), rcl=RANGER, node="Ranger")
    ev = run(root, "Ranger")
    assert ev.status == status, ev.explanation
    if status == "discharged":
        assert ev.details["examples"]["double"] > 0
        assert "held only in the implementation's IEEE-754 double arithmetic" in ev.explanation
        assert "out.d == 1000 * in.r" in ev.explanation
    else:
        assert ev.counterexample and ev.counterexample["conjunct"] == "out.d == 1000 * in.r"
