"""A client that calls a service nobody serves (issue: no wrong green): a
located warning, and no deadline chain through the call is proved
(model/system/services.py ``unserved``; calculus/deadlines.py ``chains``)."""
from __future__ import annotations

import json
import shutil
from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.calculus.deadlines import INCONCLUSIVE, PROVED, decide
from rclverify.cli.commands import main
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.system.model import build
from rclverify.model.system.services import unserved

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "safety_stop"
SERVES = "  services( std_srvs/SetBool estop serves(in.stop_req, out.stopped) )\n"


def system(text: str):  # type: ignore[no-untyped-def]
    checked = check([parse_text(text, "s.rcl")])
    return checked, build(checked)


def example_text(served: bool = True) -> str:
    text = (EXAMPLE / "contracts" / "safety_stop.rcl").read_text()
    assert SERVES in text
    return text if served else text.replace(SERVES, "")


def test_a_served_call_gives_no_warning_and_the_chain_is_proved() -> None:
    checked, model = system(example_text())
    assert unserved(checked) == []
    assert decide(checked, model, "STOP", ["Teleop", "Base"], Fraction(3, 10)).status == PROVED


def test_an_unserved_call_is_warned_located_at_the_call() -> None:
    checked, _ = system(example_text(served=False))
    [w] = unserved(checked)
    assert w.severity == "warning" and w.code == "W-unserved"
    assert str(w).startswith("s.rcl:13:13: warning: Teleop calls service 'estop', which no node serves")


def test_a_chain_through_an_unserved_request_is_not_proved() -> None:
    """Base still reads stop_req (the system model matches it by name), but
    without a server of estop Teleop's request reaches no one."""
    checked, model = system(example_text(served=False))
    assert any(lk.from_node == "Teleop" and lk.to_node == "Base" for lk in model.links)
    r = decide(checked, model, "STOP", ["Teleop", "Base"], Fraction(3, 10))
    assert r.status == INCONCLUSIVE
    assert r.reason == ("every chain goes through a call nobody answers: Teleop calls service 'estop', which no "
                        "node serves (out.stop_req is part of that call)")


def test_a_hop_triggered_by_a_response_that_never_comes_is_not_proved() -> None:
    text = example_text(served=False).replace(
        "guarantee( out.stop_req == in.button ) triggered by in.button within 50 ms",
        "guarantee( out.stop_req == in.stop_ack ) triggered by in.stop_ack within 50 ms")
    checked, model = system(text)
    r = decide(checked, model, "ACK", ["Teleop"], Fraction(1))
    assert r.status == INCONCLUSIVE and "in.stop_ack is part of that call" in r.reason


def test_a_chain_ending_in_an_unserved_request_is_not_proved() -> None:
    checked, model = system(example_text(served=False))
    r = decide(checked, model, "SEND", ["Teleop"], Fraction(1))
    assert r.status == INCONCLUSIVE and "Teleop calls service 'estop'" in r.reason


def test_check_and_deadlines_commands(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(EXAMPLE, ws, ignore=shutil.ignore_patterns("artifacts", "reports", "__pycache__"))
    rcl = ws / "contracts" / "safety_stop.rcl"
    rcl.write_text(example_text(served=False))
    assert main(["check", "-w", str(ws), str(rcl)]) == 0
    out = capsys.readouterr().out
    assert f"{rcl}:13:13: warning: Teleop calls service 'estop', which no node serves" in out or \
        "safety_stop.rcl:13:13: warning: Teleop calls service 'estop', which no node serves" in out
    assert main(["deadlines", "-w", str(ws)]) == 1
    out = capsys.readouterr().out
    assert "STOP: end-to-end deadline 300 ms along Teleop -> Base: inconclusive" in out
    assert "MOVE-FEEDBACK: end-to-end deadline 2 s along Mover: proved" in out
    diags = json.loads((ws / "artifacts" / "check" / "diagnostics.json").read_text())
    assert any(w["code"] == "W-unserved" and w["line"] == 13 for w in diags["warnings"])
