"""Evidence that goes stale says so (issue 63): a property test's verdict
is about its implementation's whole import closure within the workspace,
so a changed helper module makes the evidence stale and re-runs it
(row 2; row 1, a review bound to the text it answered, is in
tests/backends/test_review.py)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from rclverify.backends.property_tests.closure import import_closure, outside_versions

PLAN = """name: helper
contracts: [contracts/c.rcl]
requirements:
  - id: R1
    text: y is at most 100
    formal: "Agent.out.y <= 100"
    supported_by:
      - {node: Agent, guarantees: [1]}
nodes:
  Agent:
    evidence:
      - backend: property_tests
        implementation: backends/property_tests/agent.py:agent
        max_examples: 30
"""
DODO = """from pathlib import Path
from rclverify.app.tasks import build_tasks, doit_config
DOIT_CONFIG = doit_config()
globals().update(build_tasks(Path(__file__).parent))
"""


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def _verify(ws: Path) -> tuple[str, str]:
    r = subprocess.run([sys.executable, "-m", "doit", "verify"], cwd=ws, capture_output=True, text=True, timeout=300)
    assert "Traceback" not in r.stderr, r.stderr
    rep = json.loads((ws / "reports/assurance.json").read_text())
    return rep["requirements"][0]["status"], rep["obligations"][0]["status"]


def test_a_changed_helper_module_re_runs_the_property_tests(tmp_path: Path) -> None:
    _write(tmp_path, {"contracts/plan.yaml": PLAN, "dodo.py": DODO,
                      "contracts/c.rcl": "node Agent { inputs(x : INTEGER) outputs(y : INTEGER) guarantee(out.y <= 100) }\n",
                      "backends/property_tests/agent.py": "from helper import cap\n\ndef agent(x):\n    return {'y': cap(x)}\n",
                      "helper.py": "def cap(x):\n    return min(x, 100)\n"})
    assert _verify(tmp_path) == ("discharged", "discharged")
    (tmp_path / "helper.py").write_text("def cap(x):\n    return 1000\n")  # the implementation itself untouched
    assert _verify(tmp_path) == ("failed", "failed")
    from rclverify.records.store import read_obligations
    obligations = read_obligations(tmp_path / "artifacts/obligations/Agent.json")
    assert "helper.py" in obligations[0].inputs


def test_the_import_closure_follows_every_form_of_import_within_the_workspace(tmp_path: Path) -> None:
    _write(tmp_path, {
        "nodes/impl.py": ("import numpy\nimport json\nimport pkg.sibling\nfrom pkg.mod import f\n"
                          "from util import tool\nfrom lib import deep\n\ndef g():\n    import lazy\n"),
        "nodes/pkg/sibling.py": "from . import other\n",
        "nodes/pkg/__init__.py": "", "nodes/pkg/mod.py": "", "nodes/pkg/other.py": "",
        "nodes/lazy.py": "import yaml_like_but_missing\n",
        "util.py": "import nodes.pkg.mod\n",
        "lib/deep.py": "", "unrelated.py": "",
        "nodes/broken.py": "def (:\n"})
    files, outside = import_closure(tmp_path, "nodes/impl.py")
    assert files == ["lib/deep.py", "nodes/impl.py", "nodes/lazy.py", "nodes/pkg/__init__.py", "nodes/pkg/mod.py",
                     "nodes/pkg/other.py", "nodes/pkg/sibling.py", "util.py"]
    assert outside == ["numpy"]  # json is the standard library's; the missing module is unresolved, not outside
    assert outside_versions(["numpy"])["numpy"].startswith("numpy ")
    assert import_closure(tmp_path, "nodes/broken.py") == (["nodes/broken.py"], [])
