"""``first(in.x)`` in the property tests (issue 113; docs/property-tests.md,
"The first message"): a stateful implementation is judged with it TRUE on its
first step only, a function for both values.  Real Hypothesis runs, each with
its control: an implementation that ignores the first message fails, and the
counterexample names the value of ``first(in.cmd)`` it failed with."""
from __future__ import annotations

from pathlib import Path

from rclverify.app.pipeline import Workspace
from rclverify.backends.property_tests.harness import GuaranteeRun, load_implementation, read_config

RCL = '''
node Hold {
  inputs( cmd : REAL )
  outputs( out : REAL )
  guarantee( (first(in.cmd) -> out.out == 0) and (not first(in.cmd) -> out.out == in.cmd) )
}
node Floor {
  inputs( cmd : REAL )
  outputs( out : REAL )
  guarantee( first(in.cmd) -> out.out >= 0 )
}
'''
IMPL = '''
class Hold:
    def __init__(self):
        self.seen = False
    def step(self, cmd):
        out, self.seen = (cmd if self.seen else 0.0), True
        return {"out": out}

class Echo:
    def step(self, cmd):
        return {"out": cmd}

def floor(cmd):
    return {"out": abs(cmd)}

def echo(cmd):
    return {"out": cmd}
'''


def _outcome(tmp: Path, node: str, impl: str) -> object:
    (tmp / "contracts").mkdir(parents=True, exist_ok=True)
    (tmp / "contracts/c.rcl").write_text(RCL)
    (tmp / "impl.py").write_text(IMPL)
    (tmp / "contracts/plan.yaml").write_text(
        "contracts: [contracts/c.rcl]\nnodes:\n"
        f"  {node}:\n    evidence:\n      - backend: property_tests\n"
        f"        implementation: impl.py:{impl}\n        max_examples: 40\n")
    target = Workspace(tmp).target(node, 0)
    cfg = read_config(target.config, target.node, target.root)
    run = GuaranteeRun(target.checked, target.node, 1, cfg, load_implementation(target.root, cfg), target.facts)
    return run.run()


def test_a_stateful_implementation_answers_its_first_step_apart(tmp_path: Path) -> None:
    good = _outcome(tmp_path / "a", "Hold", "Hold")
    assert good.status == "discharged", good.message
    bad = _outcome(tmp_path / "b", "Hold", "Echo")  # control: the first command echoed
    assert bad.status == "failed" and bad.counterexample is not None
    assert bad.counterexample["step"] == "1" and bad.counterexample["first(in.cmd)"] == "TRUE", bad.counterexample


def test_a_function_must_meet_first_for_both_values(tmp_path: Path) -> None:
    good = _outcome(tmp_path / "a", "Floor", "floor")
    assert good.status == "discharged", good.message
    bad = _outcome(tmp_path / "b", "Floor", "echo")  # control: a negative command is its first answer
    assert bad.status == "failed" and bad.counterexample is not None
    assert bad.counterexample["first(in.cmd)"] == "TRUE", bad.counterexample
