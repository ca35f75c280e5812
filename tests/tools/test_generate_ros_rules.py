"""``rclverify generate ros2`` emits only names ROS 2 accepts (docs/generate.md, "ROS names"):
every node name and fully qualified topic, service and action name the generated node creates
is checked by rmw's and rcl's rules before anything is written; a violation is a located error
and exit 1, and no output folder or partial file is left.  tests/ros/test_ros_names_rclpy.py holds
the rules against rclpy's own validators."""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.tools.generate import rosnames

BODY = "  inputs( x : REAL )\n  outputs( y : REAL )\n"


def _node(name: str, topic: str = "p", links: str = "") -> str:
    return (f"node {name} {{\n{BODY}  topics( std_msgs/Float64 {topic} matches(in.x), std_msgs/Float64 q matches(out.y) )\n"
            f"{links}  guarantee( out.y == in.x )\n}}\n")


def _generate(tmp: Path, rcl: str, capsys: pytest.CaptureFixture[str], lang: str = "python",
              out: Path | None = None) -> tuple[int, str, Path]:
    ws = tmp / "ws"
    (ws / "contracts").mkdir(parents=True, exist_ok=True)
    (ws / "contracts" / "sys.rcl").write_text(rcl, encoding="utf-8")
    (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/sys.rcl]\n", encoding="utf-8")
    out = out or tmp / "out"
    rc = main(["generate", "ros2", "-w", str(ws), "-o", str(out), "--lang", lang, "--system", "s"])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return rc, err, out


@pytest.mark.parametrize("lang", ["python", "cpp"])
def test_a_topic_and_a_node_name_too_long_for_ros_are_located_errors_and_nothing_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], lang: str) -> None:
    rc, err, out = _generate(tmp_path, _node("N" + "n" * 299, topic="t" * 250), capsys, lang)
    assert rc == 1
    assert "contracts/sys.rcl:1:1: error: node name Nnnnnnnnnnnnnnnnnnnnnnnn...nnnnnnnnnnnnnnnnnnnnnnnn (300 " \
           "characters) cannot be a ROS 2 node name: it has 300 characters; a node name has at most 255" in err
    assert "contracts/sys.rcl:4:11: error: topic name tttttttttttttttttttttttt...tttttttttttttttttttttttt (250 " \
           "characters) cannot be a ROS 2 topic name: fully qualified it has 251 characters, and a fully " \
           "qualified topic name has at most 247" in err
    assert not out.exists()


@pytest.mark.parametrize("rcl, where, said", [
    (_node("n" * 221), "1:1", "gives the service /nnnnnnnnnnnnnnnnnnnnnnn...et_parameters_atomically (248 characters)"),
    (_node("a", topic="t" * 247), "4:11", "fully qualified it has 248 characters"),
    (_node("a", links="  actions( my_msgs/Go " + "g" * 227 + " serves(in.x, out.y, out.y) )\n"), "5:12",
     "gives the service /ggggggggggggggggggggggg...gggg/_action/cancel_goal (248 characters)"),
    (_node("a", links="  services( my_msgs/Ask " + "s" * 247 + " serves(in.x, out.y) )\n"), "5:13",
     "cannot be a ROS 2 service name: fully qualified it has 248 characters"),
    (_node("a'"), "1:1", "node name a' cannot be a ROS 2 node name: a node name holds letters, digits and '_' "
                         "only, not \"'\""),
    (_node("a" + "Ba" * 109), "1:1", "node aBaBaBaBaBaBaBaBaBaBaBaB...BaBaBaBaBaBaBaBaBaBaBaBa (219 characters) gives the generated "
                                 "file name a_ba_ba_ba_ba_ba_ba_ba_b..._ba_ba_ba_ba_ba_ba_ba_ba of 328 bytes"),
])
def test_a_name_over_a_limit_is_refused_where_it_is_declared(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                             rcl: str, where: str, said: str) -> None:
    rc, err, out = _generate(tmp_path, rcl, capsys)
    assert rc == 1 and err.startswith(f"contracts/sys.rcl:{where}: error: ") and said in err, err
    assert not out.exists()


@pytest.mark.parametrize("rcl", [
    _node("n" * 220), _node("a", topic="t" * 246),
    _node("a", links="  actions( my_msgs/Go " + "g" * 226 + " serves(in.x, out.y, out.y) )\n"),
    _node("a" + "Ba" * 72), _node("a__b_", topic="t__u_"),  # rcl and rmw accept '__' and a trailing '_'
])
def test_names_at_the_limits_generate(tmp_path: Path, capsys: pytest.CaptureFixture[str], rcl: str) -> None:
    rc, err, out = _generate(tmp_path, rcl, capsys)
    assert rc == 0, err
    assert (out / "s_bringup" / "launch" / "s.launch.py").is_file()


def test_a_write_that_fails_leaves_no_output_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    from rclverify.tools.generate import writer
    real, calls = writer.atomic_write_text, []

    def failing(path: Path, text: str) -> bool:
        calls.append(path)
        if len(calls) > 3:
            raise OSError(28, "No space left on device")
        return real(path, text)
    monkeypatch.setattr(writer, "atomic_write_text", failing)
    out = tmp_path / "made" / "for" / "out"
    rc, err, _ = _generate(tmp_path, _node("a"), capsys, out=out)
    assert rc == 1 and "No space left on device" in err and len(calls) == 4
    assert not (tmp_path / "made").exists()  # nor the folders made for it
    monkeypatch.setattr(writer, "atomic_write_text", real)
    assert _generate(tmp_path, _node("a"), capsys, out=out)[0] == 0 and (out / "a_node" / "package.xml").is_file()


def test_an_existing_output_folder_is_updated_in_place(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, _, out = _generate(tmp_path, _node("a"), capsys)
    logic = out / "a_node" / "a_node" / "logic.py"
    logic.write_text(logic.read_text(encoding="utf-8") + "# mine\n", encoding="utf-8")
    assert rc == 0 and _generate(tmp_path, _node("a", topic="r"), capsys)[0] == 0
    assert logic.read_text(encoding="utf-8").endswith("# mine\n")  # the hand-written logic is kept
    assert "'r'" in (out / "a_node" / "a_node" / "node.py").read_text(encoding="utf-8")
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".rclverify-generate")]


def test_the_rules() -> None:
    assert rosnames.node_name_problem("a" * 255) == "" and "at most 255" in rosnames.node_name_problem("a" * 256)
    assert "start with a digit" in rosnames.node_name_problem("1a")
    assert rosnames.node_name_problem("") and rosnames.node_name_problem("a-b")
    assert rosnames.full_name_problem("/a/b_c/d__") == ""
    for bad, why in [("a", "starts with '/'"), ("/a/", "end with '/'"), ("/a//b", "'//'"), ("/a/1b", "digit"),
                     ("/a b", "not ' '"), ("/" + "a" * 247, "at most 247")]:
        assert why in rosnames.full_name_problem(bad), bad
    assert rosnames.namespace_problem("/") == "" and "at most 245" in rosnames.namespace_problem("/" + "a" * 245)
    names = [n for n, _, _ in rosnames.graph_names("nd", [("topic", "t"), ("action", "g")])]
    assert "/nd/contract_verdict" in names and "/nd/set_parameters_atomically" in names and "/t" in names
    assert "/g/_action/cancel_goal" in names and "/g/_action/status" in names


def test_the_verdict_topic_is_the_one_the_templates_publish() -> None:
    templates = Path(rosnames.__file__).parent / "templates"
    assert f"VERDICT_TOPIC = '~/{rosnames.VERDICT_TOPIC}'" in (templates / "contract.py.j2").read_text()
    assert f'"~/{rosnames.VERDICT_TOPIC}"' in (templates / "cpp_node.cpp.j2").read_text()
