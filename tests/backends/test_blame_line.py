"""Blame the line (issue 64): a property-test failure names the statement
that computed the failing value, not the ``return`` that passes it on; an
output written as a literal in the wrong branch still names that line.  The
implementations are real files traced with sys.settrace."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from typing import Any

from rclverify.backends.property_tests.cause import cause_line

ARM = """\
def step(index):
    base = 0
    joint = index + 1
    checked = joint >= 0
    if not checked:
        return {"joint": base}
    return {"joint": joint}
"""

SPEED = """\
def step(distance):
    if distance < 0.5:
        return {"speed": 1.0}
    slow = distance / 2
    return {"speed": slow}
"""

CLASS = """\
class Arm:
    def __init__(self):
        self.last = 0

    def step(self, index):
        target = index * 2
        self.last = target
        return {"joint": target}
"""


def _load(tmp_path: Path, name: str, text: str, attr: str) -> Any:
    path = tmp_path / f"{name}.py"
    path.write_text(text, encoding="utf-8")
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # a class's source file is found through its module
    spec.loader.exec_module(mod)
    return getattr(mod, attr)


def test_the_assignment_that_computed_the_output(tmp_path: Path) -> None:
    step = _load(tmp_path, "arm", ARM, "step")
    assert cause_line(step, {"in.index": 5}, None, "nodes/arm.py") == "nodes/arm.py:3"  # joint = index + 1


def test_a_literal_in_the_wrong_branch_is_its_return(tmp_path: Path) -> None:
    step = _load(tmp_path, "speed", SPEED, "step")
    assert cause_line(step, {"in.distance": 0.1}, None, "speed.py") == "speed.py:3"
    assert cause_line(step, {"in.distance": 4.0}, None, "speed.py") == "speed.py:4"  # slow = distance / 2


def test_a_class_step_names_its_assignment(tmp_path: Path) -> None:
    arm = _load(tmp_path, "armc", CLASS, "Arm")
    steps = [{"in.index": 1}, {"in.index": 3}]
    assert cause_line(arm, steps, 2, "armc.py") == "armc.py:6"


# ---- Hoare: the assignment whose value breaks the post-condition -------------------------------

ARM_RCL = """\
node Arm {
  inputs( index : NATURAL )
  outputs( joint : NATURAL )
  assume( in.index <= 5 )
  guarantee( out.joint <= 5 )
}
"""

ARM_IMP = """\
var i : NATURAL;
var joint : NATURAL;
var limit : NATURAL;

limit := 5;
if i < limit then
  joint := i
else
  joint := 6
end
"""

ARM_PLAN = """\
name: "arm"
contracts: [contracts/arm.rcl]
requirements: []
nodes:
  Arm:
    evidence:
      - backend: hoare
        program: backends/hoare/arm.imp
        binding: {in.index: "i", out.joint: joint}
"""


def test_hoare_names_the_assignment_not_the_comparison(tmp_path: Path) -> None:
    import json

    from rclverify.cli.commands import main
    (tmp_path / "contracts").mkdir()
    (tmp_path / "backends" / "hoare").mkdir(parents=True)
    (tmp_path / "contracts" / "arm.rcl").write_text(ARM_RCL, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(ARM_PLAN, encoding="utf-8")
    (tmp_path / "backends" / "hoare" / "arm.imp").write_text(ARM_IMP, encoding="utf-8")
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n",
                                      encoding="utf-8")
    assert main(["verify", "-w", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "reports" / "assurance.json").read_text(encoding="utf-8"))
    d = next(x for x in report["diagnoses"] if x["kind"] == "hoare")
    assert [c["source"] for c in d["culprits"]][0] == "backends/hoare/arm.imp:9"
    assert d["culprits"][0]["text"] == "joint := 6"
    assert "backends/hoare/arm.imp:6" not in [c["source"] for c in d["culprits"]]  # `if i < limit`: no culprit
    row = next(g for g in report["problems"] if d["id"] in [m["id"] for m in g["members"]])
    assert row["key"] == ["line:backends/hoare/arm.imp:9"]


def test_the_run_names_nothing_it_cannot_replay() -> None:
    from rclverify.backends.hoare import lang
    from rclverify.backends.hoare.culprit_assign import breaking_assignments, run
    prog = lang.parse_program(ARM_IMP, "arm.imp")
    final, last = run(prog, {"i": 5})
    assert final["joint"] == 6 and last["joint"].loc.line == 9
    assert run(prog, {"i": 2})[1]["joint"].loc.line == 7
    # Z3 said another final value: not this run, nothing named
    assert breaking_assignments(prog, {"i": 5, "joint (final)": 7}, {"out.joint": "joint"}, ARM_IMP) == []
    loop = lang.parse_program("var x : INTEGER;\nwhile x < 10 invariant TRUE do\n  x := x + 1\nend\n", "l.imp")
    assert run(loop, {"x": 0})[0]["x"] == 10
    ext = lang.parse_program("extern f : REAL --> REAL;\nvar x : REAL;\nvar y : REAL;\ny := f(x)\n", "e.imp")
    assert breaking_assignments(ext, {"x": 1, "y (final)": 2}, {"out.y": "y"}, "") == []


# ---- a generated node: the handler of logic.py that published the violating message ------------

GEN_RCL = """\
node ArmDriver {
  inputs( estop : BOOL, target : REAL )
  outputs( command : REAL )
  topics( std_msgs/Bool estop matches(in.estop),
          std_msgs/Float64 target matches(in.target),
          std_msgs/Float64 command matches(out.command) )
  assume( 0 <= in.target and in.target <= 10 )
  guarantee( in.estop -> out.command == 0 )
}
"""

#: what the user wrote in logic.py: a correct step, and an e-stop handler that re-sends the last command
STEP = '''def step(estop, target):
    """The outputs for these inputs (RCL values, docs/values.md): ``{output name: value}``."""
    return {"command": 0.0 if estop else target}
'''
ON_INPUT = '''def on_input(node, var, msg):
    """A message for contract input ``var`` (``'in.x'``) arrived; publish the outputs it decides."""
    if var == "in.estop":
        node.publish_value("out.command", getattr(node, "last", 0.0))
        return
    for name, value in _run(node).items():
        node.last = value
        node.publish_value(f'out.{name}', value)
'''

RUN = "".join(line + "\n" for line in (
    '{"topic": "target", "time": 1.0, "data": 5.0}',
    '{"topic": "estop", "time": 1.5, "data": false}',
    '{"topic": "command", "time": 1.51, "data": 5.0}',
    '{"topic": "estop", "time": 2.0, "data": true}',
    '{"topic": "command", "time": 2.01, "data": 5.0}'))


def test_a_run_of_a_generated_node_names_its_handler(tmp_path: Path) -> None:
    import json
    import re

    import yaml

    from rclverify.cli.commands import main
    (tmp_path / "contracts").mkdir()
    (tmp_path / "runs").mkdir()
    (tmp_path / "contracts" / "arm.rcl").write_text(GEN_RCL, encoding="utf-8")
    (tmp_path / "contracts" / "plan.yaml").write_text(
        'name: "gen"\ncontracts: [contracts/arm.rcl]\nrequirements: []\nnodes:\n  ArmDriver: {}\n', encoding="utf-8")
    (tmp_path / "dodo.py").write_text("from pathlib import Path\nfrom rclverify.app.tasks import build_tasks, doit_config\n"
                                      "DOIT_CONFIG = doit_config()\nglobals().update(build_tasks(Path(__file__).parent))\n",
                                      encoding="utf-8")
    assert main(["generate", "ros2", "-w", str(tmp_path), "-o", str(tmp_path / "gen")]) == 0
    logic = tmp_path / "gen" / "arm_driver" / "arm_driver" / "logic.py"
    text = logic.read_text(encoding="utf-8")
    text = re.sub(r"def step\(estop, target\):\n(?:    .*\n)+", STEP, text, count=1)
    text = re.sub(r"def on_input\(node, var, msg\):\n(?:    .*\n)+", ON_INPUT, text, count=1)
    logic.write_text(text, encoding="utf-8")
    lines = text.splitlines()
    handler_line = lines.index("def on_input(node, var, msg):") + 1
    early = handler_line + 4  # the bare `return` after re-sending the last command
    assert lines[early - 1].strip() == "return"
    (tmp_path / "runs" / "run.jsonl").write_text(RUN, encoding="utf-8")
    plan = yaml.safe_load((tmp_path / "contracts" / "plan.yaml").read_text(encoding="utf-8"))
    plan["nodes"] = {"ArmDriver": {"evidence": [{"backend": "monitors", "mapping": "gen/rclverify_mapping.yaml",
                                                 "traces": ["runs/run.jsonl"]}]}}
    (tmp_path / "contracts" / "plan.yaml").write_text(yaml.safe_dump(plan), encoding="utf-8")
    assert main(["verify", "-w", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "reports" / "assurance.json").read_text(encoding="utf-8"))
    d = next(x for x in report["diagnoses"] if x["kind"] == "monitor")
    where = f"gen/arm_driver/arm_driver/logic.py:{handler_line}"
    assert d["culprits"][0]["source"] == where and d["culprits"][0]["text"] == "on_input"
    assert f"returns early at line {early}" in d["sentence"] and "called for in.estop" in d["culprits"][0]["what"]
    row = next(g for g in report["problems"] if d["id"] in [m["id"] for m in g["members"]])
    assert row["key"] == [f"line:{where}"]  # the handler, not the contract
    assert row["culprits"][0]["node"] == "ArmDriver"  # the node whose code it is: marked a culprit
    from rclverify.report.culprits import culprit_nodes
    assert culprit_nodes(report["problems"]) == {"ArmDriver"}


def _random_program(rng: Any) -> tuple[str, str]:
    """A random program over x, y, z (assignments and nested ifs) as the Hoare
    language's text and as Python that records the line of each assignment."""
    imp = ["var x : INTEGER;", "var y : INTEGER;", "var z : INTEGER;"]
    py = ["last = {}"]

    def expr() -> str:
        a, b = rng.choice("xyz"), rng.choice(["x", "y", "z", str(rng.randint(0, 9))])
        return f"{a} {rng.choice('+-*')} {b}"

    def block(depth: int, indent: int) -> None:
        for _ in range(rng.randint(1, 3)):
            if depth < 2 and rng.random() < 0.3:
                cond = f"{rng.choice('xyz')} {rng.choice(['<', '<=', '==', '>'])} {rng.randint(-5, 15)}"
                imp.append(" " * indent + f"if {cond} then")
                py.append(" " * indent + f"if {cond}:")
                block(depth + 1, indent + 2)
                imp.append(" " * indent + "else")
                py.append(" " * indent + "else:")
                block(depth + 1, indent + 2)
                imp.append(" " * indent + "end")
                py.append(" " * indent + "pass")  # keeps the two texts line for line
            else:
                v, e = rng.choice("xyz"), expr()
                imp.append(" " * indent + f"{v} := {e}")
                py.append(" " * indent + f"{v} = {e}; last['{v}'] = {len(imp)}")
    block(0, 0)
    return "\n".join(imp) + "\n", "\n".join(py) + "\n"


def test_the_program_run_agrees_with_python_on_random_programs() -> None:
    """Oracle: each random program run by culprit_assign.run gives the final values and the line of
    the last assignment to each variable that Python's own execution of the same program gives."""
    import random

    from rclverify.backends.hoare import lang
    from rclverify.backends.hoare.culprit_assign import run
    rng = random.Random(64)
    for _ in range(60):
        imp, py = _random_program(rng)
        start = {"x": rng.randint(-3, 12), "y": rng.randint(-3, 12), "z": rng.randint(-3, 12)}
        env: dict[str, Any] = dict(start)
        exec(py, {}, env)  # noqa: S102 - the oracle: Python runs the program it was written as
        final, last = run(lang.parse_program(imp, "r.imp"), start)
        assert {v: final[v] for v in "xyz"} == {v: env[v] for v in "xyz"}, imp
        assert {v: a.loc.line for v, a in last.items()} == env["last"], imp


def test_the_traced_line_agrees_with_python_on_random_functions(tmp_path: Path) -> None:
    """Oracle: for random functions of assignments and branches returning one local, the line named
    is the last executed assignment of the returned local, as the instrumented twin of each function
    records it (small ints included: one object wherever they are computed)."""
    import random
    rng = random.Random(6464)
    for n in range(40):
        body, twin = ["def step(x):", "    a = 0", "    b = 1"], ["def twin(x):", "    last = {'a': 2, 'b': 3}",
                                                                "    a = 0", "    b = 1"]
        for _ in range(rng.randint(1, 4)):
            v, e = rng.choice("ab"), rng.choice(["x + 1", "x * 2", "a + b", "4", "x - a", "b"])
            if rng.random() < 0.4:
                cond = f"x > {rng.randint(-2, 6)}"
                body += [f"    if {cond}:", f"        {v} = {e}"]
                twin += [f"    if {cond}:", f"        {v} = {e}; last['{v}'] = {len(body)}"]
            else:
                body.append(f"    {v} = {e}")
                twin.append(f"    {v} = {e}; last['{v}'] = {len(body)}")
        out = rng.choice("ab")
        body.append(f"    return {{'out': {out}}}")
        twin.append(f"    return last['{out}']")
        step = _load(tmp_path, f"rnd{n}", "\n".join(body) + "\n", "step")
        scope: dict[str, Any] = {}
        exec("\n".join(twin) + "\n", scope)  # noqa: S102 - the oracle
        x = rng.randint(-3, 8)
        assert cause_line(step, {"in.x": x}, None, "s.py") == f"s.py:{scope['twin'](x)}", "\n".join(body)


def test_a_run_and_a_property_test_of_one_step_name_the_line_that_computed_it() -> None:
    from rclverify.diagnosis.evidence_records import _computed_line
    from rclverify.records.evidence_rows import EvidenceRow
    from rclverify.records.obligations import ObligationRow

    def ob(k: int) -> ObligationRow:
        return ObligationRow(f"T.g{k}.property_tests.e0", "T", k, "property_tests", "testing", "e0", "", "", "", "failed")

    def ev(k: int, cause: str) -> EvidenceRow:
        return EvidenceRow(f"T.g{k}.property_tests.e0", "property_tests", "testing", "failed", "", "", "", 0.0, "",
                           {"cause": cause}, [], "")
    obligations, evidence = [ob(1), ob(2)], [ev(1, "gen/t/t/logic.py:18"), ev(2, "gen/t/t/other.py:3")]
    assert _computed_line(obligations, evidence, "T", 1, "gen/t/t/logic.py") == "gen/t/t/logic.py:18"
    assert _computed_line(obligations, evidence, "T", 2, "gen/t/t/logic.py") == ""  # another file: not this handler's code
    assert _computed_line(obligations, evidence, "U", 1, "gen/t/t/logic.py") == ""
