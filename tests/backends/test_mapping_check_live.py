"""One mapping check for ``doit verify`` and the live monitor (issue 107; docs/monitors.md, "Field
paths"): an action's feedback ``int32[] sequence`` mapped whole (``fields: [sequence]``) to a
``seq(INTEGER)`` variable is accepted, as an array mapped to a topic's ``seq(T)`` variable always was;
the control, the same array mapped to an ``INTEGER`` variable, is still refused at its line and
column, by :func:`~rclverify.backends.monitors.fieldpaths.check_field_paths` (what ``doit verify``
calls) and by ``rclverify monitor --live`` (which calls it before it reaches any middleware: one
located line, exit 2, no traceback).  In-process; the action's definition is the workspace's."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.backends.monitors.fieldpaths import check_field_paths
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check

RCL = """node Counter {
  inputs( order : INTEGER )
  outputs( seen : FEEDBACK, final : seq(INTEGER) )
  actions( demo_actions/Count count serves(in.order, out.seen, out.final) )
  assume( in.order >= 1 )
  guarantee( TRUE )
}
"""
COUNT = "int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n"
MAPPING = """\
msg_dirs: [interfaces]
topics:
  count/feedback: {fields: [sequence]}
  count/result: {fields: [sequence]}
"""


def _ws(tmp: Path, feedback: str) -> tuple[Path, object]:
    ws = tmp / "ws"
    (ws / "interfaces/demo_actions/action").mkdir(parents=True)
    (ws / "interfaces/demo_actions/action/Count.action").write_text(COUNT)
    (ws / "mapping.yaml").write_text(MAPPING)
    rcl = RCL.replace("FEEDBACK", feedback)
    (ws / "contracts").mkdir()
    (ws / "contracts/c.rcl").write_text(rcl)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    return ws, check([parse_text(rcl, "c.rcl")])


def test_an_array_fills_an_actions_sequence_variable(tmp_path: Path) -> None:
    ws, checked = _ws(tmp_path, "seq(INTEGER)")
    assert check_field_paths(ws, "mapping.yaml", ["interfaces"], checked) == []  # type: ignore[arg-type]


def test_an_array_mapped_to_a_single_value_is_still_refused(tmp_path: Path) -> None:
    ws, checked = _ws(tmp_path, "INTEGER")
    diags = [str(d) for d in check_field_paths(ws, "mapping.yaml", ["interfaces"], checked)]  # type: ignore[arg-type]
    assert len(diags) == 1 and diags[0].startswith("mapping.yaml:3:29: error: topic count/feedback: "), diags
    assert "an array (int32[]) cannot fill a single value" in diags[0], diags


@pytest.mark.parametrize("ros", ["1", "2"])
def test_the_live_monitor_refuses_what_doit_verify_refuses(tmp_path: Path, ros: str,
                                                           capsys: pytest.CaptureFixture[str]) -> None:
    ws, _ = _ws(tmp_path, "INTEGER")
    code = main(["monitor", "-w", str(ws), "--live", "--ros", ros, "--mapping", "mapping.yaml",
                 "--log", str(tmp_path / "live.jsonl"), "--duration", "0.1"])
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert code == 2 and len(lines) == 1, out
    assert lines[0].startswith("mapping.yaml:3:29: error: topic count/feedback: ") and "cannot fill a single" in lines[0]
    assert not (tmp_path / "live.jsonl").exists()  # refused before the run started
