"""Warnings a user can answer (issue 64): redundancy that respects deadlines
and triggers, and acknowledgements of lint and health warnings in the plan."""
from __future__ import annotations

from rclverify.health.shape import shape_findings
from rclverify.rcl.parser import parse_text
from rclverify.rcl.typecheck import check

TIMED = """
node Stopper {
  inputs( estop : BOOL, button : BOOL )
  outputs( halt : BOOL )
  assume( TRUE )
  guarantee( in.estop -> out.halt )
  guarantee( in.estop -> out.halt ) triggered by in.estop within 20 ms
  guarantee( in.estop -> out.halt ) triggered by in.estop
  guarantee( in.estop -> out.halt ) triggered by in.estop within 10 ms
}
"""


def _redundant(text: str) -> set[str]:
    checked = check([parse_text(text, "s.rcl")])
    return {f.id for f in shape_findings(checked, "Stopper") if f.check == "redundant"}


def test_a_timed_guarantee_is_never_implied_by_an_untimed_one():
    found = _redundant(TIMED)
    # g2 (20 ms) follows only from g4 (10 ms); g3 (triggered, untimed) from g2 and g4;
    # g4 from nothing as tight; g1 (every message) from no guarantee on responses only
    assert found == {"Stopper.g2.c1.redundant", "Stopper.g3.c1.redundant"}


def test_without_the_tighter_deadline_the_timed_guarantee_stands():
    text = TIMED.replace("  guarantee( in.estop -> out.halt ) triggered by in.estop within 10 ms\n", "")
    # the case: g3 (untimed) would have flagged g2 (20 ms); deleting g2 would lose the deadline
    assert _redundant(text) == {"Stopper.g3.c1.redundant"}


def test_a_triggered_guarantee_is_implied_by_one_of_the_same_trigger_only():
    text = TIMED.replace("triggered by in.estop\n", "triggered by in.button\n")
    assert "Stopper.g3.c1.redundant" not in _redundant(text)
    untriggered = TIMED.replace("  guarantee( in.estop -> out.halt )\n", "  guarantee( in.estop -> out.halt and in.button -> out.halt )\n")
    assert "Stopper.g1.c1.redundant" not in _redundant(untriggered)
