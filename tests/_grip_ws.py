"""A two-node gripper cell written for the issue-64 tests: a supervisor that
allows 45 N to a gripper driver that assumes at most 40 N and is correct for
what it assumes.  The force requirement is refuted only because of the
supervisor's bound (the side condition of the driver's assumption fails), and
a second requirement, proved, carries an ``assuming:`` (a nested list in
assurance.md)."""
from __future__ import annotations

from pathlib import Path

CELL = """\
// A supervisor sets the grip force; the gripper driver applies it.
node Supervisor {
  inputs( request : REAL )
  outputs( force : REAL )
  assume( 0 <= in.request and in.request <= 100 )
  guarantee( 0 <= out.force and out.force <= 45 )
}

node GripperDriver {
  inputs( force : REAL )
  outputs( applied : REAL )
  assume( 0 <= in.force and in.force <= 40 )
  guarantee( 0 <= out.applied and out.applied <= in.force and out.applied <= 60 )
}
"""

PLAN = """\
name: "grip"
contracts:
  - contracts/cell.rcl
requirements:
  - id: REQ-FORCE
    text: The applied grip force never exceeds 40 N.
    formal: "GripperDriver.out.applied <= 40"
    supported_by:
      - {node: GripperDriver, guarantees: [1]}
  - id: REQ-LOW
    text: A low force stays low.
    formal: "GripperDriver.out.applied <= 10"
    assuming: ["GripperDriver.in.force <= 10"]
    supported_by:
      - {node: GripperDriver, guarantees: [1]}
connections: []
environment: {}
nodes:
  Supervisor: {}
  GripperDriver: {}
"""

DODO = """\
from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
"""


def make(root: Path) -> Path:
    """Write the workspace under ``root`` and return it."""
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "cell.rcl").write_text(CELL, encoding="utf-8")
    (root / "contracts" / "plan.yaml").write_text(PLAN, encoding="utf-8")
    (root / "dodo.py").write_text(DODO, encoding="utf-8")
    return root
