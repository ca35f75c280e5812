"""Services, actions, triggers and deadlines in RCL (issue 33, step 1):
syntax, round trip through ``fmt``, LaTeX, and located type errors."""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.lang import ast
from rclverify.lang.errors import RclError
from rclverify.lang.latex import to_latex
from rclverify.lang.parser import parse_text
from rclverify.lang.printer import to_rcl
from rclverify.lang.timing import seconds
from rclverify.lang.typecheck import check

REPO = Path(__file__).resolve().parents[2]

BASE = """\
node Base {
  inputs( stop_req : BOOL, goal : REAL )
  outputs( stop_ack : BOOL, fb : REAL, res : BOOL )
  services( std_srvs/SetBool estop serves(in.stop_req, out.stop_ack) )
  actions( demo_msgs/Move move serves(in.goal, out.fb, out.res) )
  assume( TRUE )
  guarantee( in.stop_req -> out.stop_ack ) triggered by in.stop_req within 200 ms
  G( out.fb >= 0 ) triggered by in.goal within 2 s
  guarantee( out.res or not out.res )
}
node Client {
  inputs( ack : BOOL )
  outputs( req : BOOL )
  services( std_srvs/SetBool estop calls(out.req, in.ack) )
  guarantee( out.req == TRUE )
}
"""


def errors_of(text: str) -> list[str]:
    with pytest.raises(RclError) as exc:
        check([parse_text(text, "f.rcl")])
    return [str(d) for d in exc.value.diagnostics]


def test_links_triggers_and_deadlines_are_read() -> None:
    spec = parse_text(BASE, "f.rcl")
    base = spec.nodes[0]
    assert [(lk.kind, lk.ros_type, lk.name, lk.role, [v.qualified for v in lk.parts]) for lk in base.links] == [
        ("service", "std_srvs/SetBool", "estop", "serves", ["in.stop_req", "out.stop_ack"]),
        ("action", "demo_msgs/Move", "move", "serves", ["in.goal", "out.fb", "out.res"])]
    g1, g2, g3 = base.guarantees
    assert g1.trigger is not None and g1.trigger.qualified == "in.stop_req"
    assert g1.deadline == ast.Deadline("200", "ms") and seconds(g1.deadline) == Fraction(1, 5)
    assert g2.deadline is not None and seconds(g2.deadline) == 2
    assert g3.trigger is None and g3.deadline is None
    assert (g1.deadline.loc.line, g1.deadline.loc.col) == (7, 69)
    check([spec])  # well typed, client and server alike


def test_fmt_round_trip_keeps_the_new_constructs() -> None:
    spec = parse_text(BASE, "f.rcl")
    text = to_rcl(spec)
    assert "services( std_srvs/SetBool estop serves(in.stop_req, out.stop_ack) )" in text
    assert "guarantee( out.fb >= 0 ) triggered by in.goal within 2 s" in text
    again = parse_text(text, "g.rcl")
    assert again.nodes == spec.nodes
    assert to_rcl(again) == text


def test_latex_shows_links_and_deadlines() -> None:
    tex = to_latex(parse_text(BASE, "f.rcl"))
    assert r"serves($\mathit{in.stop\_req}$, $\mathit{out.stop\_ack}$)" in tex
    assert r"triggered by $\mathit{in.goal}$ within 2~\textrm{s}" in tex


def test_untimed_contracts_keep_their_meaning() -> None:
    spec = parse_text((REPO / "contracts" / "remote_inspection.rcl").read_text(), "r.rcl")
    for n in spec.nodes:
        assert n.links == ()
        assert all(c.trigger is None and c.deadline is None for c in n.guarantees)
    # the original tool's short forms still parse, timed or not
    short = parse_text("node n { inputs(a : REAL) outputs(o : REAL) A(a > 0) G(o > a) }")
    assert short.nodes[0].guarantees[0].deadline is None


def test_deadline_without_unit_is_located() -> None:
    text = BASE.replace("within 200 ms", "within 200")
    assert errors_of(text) == ["f.rcl:7:69: error: deadline 'within 200' has no unit; write e.g. "
                               "'within 200 ms' (units: ns, us, ms, s, min, h)"]


def test_unknown_unit_and_deadline_without_trigger() -> None:
    text = BASE.replace("within 200 ms", "within 200 sec").replace("triggered by in.goal within 2 s",
                                                                    "within 2 s")
    msgs = errors_of(text)
    assert msgs[0].startswith("f.rcl:7:69: error: unknown time unit 'sec'")
    assert msgs[1].startswith("f.rcl:8:20: error: a deadline needs 'triggered by in.x'")


def test_response_used_as_input_of_its_own_server_is_located() -> None:
    text = BASE.replace("serves(in.stop_req, out.stop_ack)", "serves(in.stop_req, in.stop_req)")
    assert errors_of(text) == [
        "f.rcl:4:56: error: service response in.stop_req used as an input of its own server Base: "
        "a server writes the response, so it must be an output (out.x)"]


def test_client_side_is_the_mirror_image() -> None:
    text = BASE.replace("calls(out.req, in.ack)", "calls(in.ack, out.req)")
    msgs = errors_of(text)
    assert len(msgs) == 2
    assert msgs[0].startswith("f.rcl:14:42: error: service request in.ack used as an input of its own client")
    assert msgs[1].startswith("f.rcl:14:50: error: service response out.req used as an output of its own client")


def test_triggered_by_an_output_is_located() -> None:
    text = BASE.replace("triggered by in.goal", "triggered by out.fb")
    assert errors_of(text) == ["f.rcl:8:33: error: 'triggered by' names output out.fb; a guarantee is "
                               "triggered by an input of node Base"]


def test_link_to_an_undeclared_variable_and_duplicate_link() -> None:
    text = BASE.replace("serves(in.goal, out.fb, out.res)", "serves(in.goal, out.fb, out.nope)")
    assert errors_of(text)[0].startswith("f.rcl:5:56: error: the result of action 'move' must be an input or output")
    dup = BASE.replace("demo_msgs/Move move", "demo_msgs/Move estop")
    assert "is linked twice in node Base" in errors_of(dup)[0]


def test_cli_check_reports_located_errors_without_traceback(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "bad.rcl"
    f.write_text(BASE.replace("within 200 ms", "within 200"))
    assert main(["check", str(f)]) == 1
    err = capsys.readouterr().err
    assert f"{f}:7:69: error: deadline 'within 200' has no unit" in err
    assert "Traceback" not in err


def test_a_triggered_guarantee_must_mention_an_output() -> None:
    text = BASE.replace("guarantee( out.res or not out.res )", "guarantee( in.goal >= 0 ) triggered by in.goal")
    assert errors_of(text) == ["f.rcl:9:42: error: a guarantee triggered by in.goal must mention an output "
                               "(out.y): the output is what answers the trigger"]


def test_zero_and_huge_deadlines_are_refused_quickly() -> None:
    for amount in ("0", "1e999999999"):
        msgs = errors_of(BASE.replace("within 200 ms", f"within {amount} ms"))
        assert msgs == ["f.rcl:7:69: error: a deadline must be positive and at most 1e+09 ms"]
