"""A context constant is evaluated with the definedness conditions of any expression
(semantics/definedness.py, :func:`constant_faults`; docs/rcl-language.md, "Constants").

``K = 10 / Zero`` with ``Zero = 0`` has no value: ``rclverify check`` and the workspace
``doit verify`` loads (:attr:`rclverify.stages.workspace.Workspace.checked`) refuse it at the
constant's definition, ``file:line:col``, exit 1 and no traceback.  The control,
``K = 10 / Two``, checks.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.semantics.definedness import constant_faults
from rclverify.stages.workspace import Workspace

CONTEXT = """context {
  Zero : REAL = 0 ;
  Two : REAL = 2 ;
  K : REAL = 10 / DIVISOR ;
  Half : REAL = 1 / K ;
}
"""
NODE = """node Gate {
  inputs( p : REAL )
  outputs( low : BOOL )
  guarantee( out.low <=> in.p <= K )
}
"""


def _workspace(root: Path, divisor: str) -> Path:
    (root / "contracts").mkdir(parents=True)
    (root / "contracts" / "context.rcl").write_text(CONTEXT.replace("DIVISOR", divisor))
    (root / "contracts" / "gate.rcl").write_text(NODE)
    (root / "contracts" / "plan.yaml").write_text("contracts: [contracts/context.rcl, contracts/gate.rcl]\n")
    return root


def test_an_undefined_constant_is_an_error_at_its_definition() -> None:
    checked = check([parse_text(CONTEXT.replace("DIVISOR", "Zero"), "c.rcl"), parse_text(NODE, "g.rcl")])
    faults = constant_faults(checked)
    # only K: Half = 1 / K reads an undefined constant, which is reported at K's own definition
    assert [str(d) for d in faults] == [
        "c.rcl:4:3: error: constant K is undefined: the division at c.rcl:4:14 needs Zero != 0, which is false "
        "(Zero = 0)"]


def test_the_control_a_nonzero_divisor_is_defined() -> None:
    checked = check([parse_text(CONTEXT.replace("DIVISOR", "Two"), "c.rcl"), parse_text(NODE, "g.rcl")])
    assert constant_faults(checked) == []


@pytest.mark.parametrize("divisor, code", [("Zero", 1), ("Two", 0)])
def test_rclverify_check(tmp_path: Path, capsys: pytest.CaptureFixture[str], divisor: str, code: int) -> None:
    root = _workspace(tmp_path, divisor)
    files = [str(root / "contracts" / "context.rcl"), str(root / "contracts" / "gate.rcl")]
    assert main(["check", "-w", str(root), *files]) == code
    err = capsys.readouterr().err
    assert ("context.rcl:4:3: error: constant K is undefined" in err) is (code == 1), err
    assert "Traceback" not in err


@pytest.mark.parametrize("divisor", ["Zero", "Two"])
def test_the_workspace_doit_verify_loads(tmp_path: Path, divisor: str) -> None:
    ws = Workspace(_workspace(tmp_path, divisor))
    if divisor == "Two":
        assert "Gate" in ws.checked.nodes
        return
    with pytest.raises(RclError) as exc:
        ws.checked
    assert [f"{d.loc.file}:{d.loc.line}:{d.loc.col}" for d in exc.value.diagnostics] == ["contracts/context.rcl:4:3"]
