"""``rclverify ros scan`` never ends in a traceback: mutated launch files,
package.xml files, message files and node sources give located notes (or
nothing), never an exception (docs/ros.md)."""
from __future__ import annotations

import shutil
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rclverify.cli.commands import main
from rclverify.ros.graph.scan import scan

WS = Path(__file__).parent.parent / "data" / "ros" / "catkin_ws" / "src"
TARGETS = ["rover_control/launch/rover.launch", "rover_control/launch/control.launch", "rover_msgs/package.xml",
           "rover_msgs/msg/Status.msg", "rover_msgs/msg/Reading.msg", "rover_sensing/scripts/sensor.py",
           "rover_control/src/controller.cpp", "rover_control/CMakeLists.txt"]
JUNK = ["<", ">", "\"", "$(", ")", "$(arg robot)", "$(find nowhere)", "<include file=\"rover.launch\"/>", "[", "]",
        "---", "=", "\x00", "\ufeff", "uint8 X=", "Header", "/", "::", "<node/>", "if=\"maybe\"", "\n", "é", "&x;"]


@st.composite
def mutation(draw: st.DrawFn) -> tuple[str, list[tuple[int, int, str]]]:
    target = draw(st.sampled_from(TARGETS))
    edits = draw(st.lists(st.tuples(st.integers(0, 4000), st.integers(0, 40),
                                    st.one_of(st.sampled_from(JUNK), st.text(max_size=8))), min_size=1, max_size=4))
    return target, edits


def _mutate(text: str, edits: list[tuple[int, int, str]]) -> str:
    for pos, cut, junk in edits:
        pos = pos % (len(text) + 1)
        text = text[:pos] + junk + text[pos + cut:]
    return text


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(m=mutation())
def test_mutated_workspace_never_raises(tmp_path_factory, m) -> None:  # type: ignore[no-untyped-def]
    target, edits = m
    ws = tmp_path_factory.mktemp("ws")
    shutil.copytree(WS, ws / "src")
    f = ws / "src" / target
    f.write_text(_mutate(f.read_text(encoding="utf-8"), edits), encoding="utf-8", errors="surrogatepass")
    res = scan([ws], [ws / "src/rover_control/launch/rover.launch"], base=ws, standard=False)
    for n in res.graph.notes:  # every note is located in a scanned file
        assert n.src.line >= 1 and n.src.file
    res.graph.to_json()


def test_cli_on_garbage_files_exits_without_traceback(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    pkg = tmp_path / "ws" / "bad"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "launch").mkdir()
    (pkg / "package.xml").write_bytes(b"<package format='2'><name>bad</name><version>x.y</version></package>")
    good = tmp_path / "ws" / "good"
    (good / "msg").mkdir(parents=True)
    (good / "package.xml").write_text((WS / "rover_msgs/package.xml").read_text().replace("rover_msgs", "good"))
    (good / "msg" / "Bad.msg").write_text("# comment\nint33 x\nstring[ y\n")
    (pkg / "launch" / "a.launch").write_text("<launch><include file='a.launch'/><node pkg=")
    (pkg / "launch" / "b.launch").write_text("<launch><include file='b.launch'/></launch>")
    (pkg / "launch" / "c.launch.py").write_text("def generate_launch_description(:\n")
    (pkg / "launch" / "d.launch.yaml").write_text("launch: [ {node: *x} ]")
    rc = main(["ros", "scan", str(tmp_path / "ws"), "--json", str(tmp_path / "g.json")]
              + [a for f in ("a.launch", "b.launch", "c.launch.py", "d.launch.yaml")
                 for a in ("--launch", str(pkg / "launch" / f))])
    err = capsys.readouterr().err
    assert rc == 1 and "Traceback" not in err
    assert "package.xml:1:1: error: invalid package.xml" in err
    assert "a.launch:1:" in err and "error: not well-formed XML" in err
    assert "b.launch:1:1: warning: include cycle" in err
    assert "c.launch.py:1:" in err and "d.launch.yaml:1:" in err
    assert "Bad.msg:" in err and "error: bad msg definition good/msg/Bad" in err
