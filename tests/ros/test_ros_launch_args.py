"""Launch arguments across includes and groups, as ROS 2 launch runs them
(docs/ros.md, "Launch arguments across includes"), each with its control:

* an include's ``launch_arguments`` override the included file's
  ``DeclareLaunchArgument`` defaults (control: none given, the default);
* an included ROS 2 file sees every launch configuration set before it, also
  one it does not declare (control: a ROS 1 ``<include>`` passes only its
  ``<arg>`` children, so ``$(arg x)`` there has no value and is said);
* what an include sets stays after it in the including file (launch's
  ``IncludeLaunchDescription`` sets its arguments in the including context);
  control: the include inside a ``GroupAction`` (scoped), after which the
  including file's own value is back;
* ``GroupAction(scoped=False)`` keeps what it sets (control: scoped, it does
  not); ``GroupAction(forwarding=False, launch_configurations={...})`` starts
  from the kept configurations alone, its namespace cleared (control:
  forwarding, the outer ones are seen); the XML forms ``<group
  forwarding="false"><keep .../>``;
* ``PushLaunchConfigurations`` / ``PopLaunchConfigurations`` restore what was
  set between them (control: without them it stays; a pop with no push is
  said), ``ResetLaunchConfigurations({k: v})`` keeps only ``k`` (control: no
  reset).

Packages are written into a temporary directory and read by the scan.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from test_ros_launch_run import CMAKE, LISTENER, PKG, PY_HEAD, TALKER, _write

from rclverify.ros.extract.model import Graph
from rclverify.ros.graph.scan import scan

HEAD = PY_HEAD + ("from launch.actions import IncludeLaunchDescription, SetLaunchConfiguration\n"
                  "from launch.actions import PopLaunchConfigurations, PushLaunchConfigurations, "
                  "ResetLaunchConfigurations\n"
                  "from launch.launch_description_sources import PythonLaunchDescriptionSource\n"
                  "from launch_ros.substitutions import FindPackageShare\n\n\n")
INCLUDE = ("IncludeLaunchDescription(PythonLaunchDescriptionSource(\n"
           "    os.path.join(FindPackageShare('demo').perform(None), 'launch', '{file}')){args}),")


@pytest.fixture(scope="module")
def ws(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("launchargs")
    _write(root / "ws" / "demo", {
        "package.xml": PKG.format(name="demo", tool="ament_cmake", export=""),
        "CMakeLists.txt": CMAKE.format(name="demo") + "add_executable(talker src/talker.cpp)\n"
                                                      "add_executable(listener src/listener.cpp)\n",
        "src/talker.cpp": TALKER, "src/listener.cpp": LISTENER})
    return root


def _py(ws: Path, name: str, body: str) -> Path:
    f = ws / "ws" / "demo" / "launch" / name
    f.parent.mkdir(exist_ok=True)
    f.write_text(HEAD + "def generate_launch_description():\n    return LaunchDescription([\n"
                 + "".join(f"        {line}\n" for line in body.strip().splitlines()) + "    ])\n")
    return f


def _include(file: str, args: str = "") -> str:
    return INCLUDE.format(file=file, args=f",\n    launch_arguments={{{args}}}.items()" if args else "")


def _graph(ws: Path, lf: Path) -> Graph:
    return scan([ws / "ws"], [lf], None, base=ws, standard=False).graph


def _said(g: Graph) -> list[str]:
    return [str(n) for n in g.notes]


ROBOT = ("DeclareLaunchArgument('robot', default_value='fallback'),\n"
         "Node(package='demo', executable='talker', namespace=LaunchConfiguration('robot')),")
UNDECLARED = "Node(package='demo', executable='listener', namespace=LaunchConfiguration('fleet')),"


def test_an_include_argument_overrides_the_included_default(ws: Path) -> None:
    _py(ws, "robot.launch.py", ROBOT)
    g = _graph(ws, _py(ws, "top.launch.py", _include("robot.launch.py", "'robot': 'r2'")))
    assert sorted(g.nodes) == ["/r2/talker"] and _said(g) == []
    # control: no argument given: the included file's default
    g = _graph(ws, _py(ws, "top.launch.py", _include("robot.launch.py")))
    assert sorted(g.nodes) == ["/fallback/talker"] and _said(g) == []


def test_an_included_file_sees_the_configurations_set_before_it(ws: Path) -> None:
    _py(ws, "fleet.launch.py", UNDECLARED)
    g = _graph(ws, _py(ws, "top.launch.py", "DeclareLaunchArgument('fleet', default_value='blue'),\n"
                                            + _include("fleet.launch.py")))
    assert sorted(g.nodes) == ["/blue/listener"] and _said(g) == []


def test_a_ros1_include_passes_only_its_args(ws: Path) -> None:
    # control: roslaunch gives an included file only the <arg>s the include passes
    (ws / "ws/demo/launch/inner.launch").write_text(
        '<launch><node pkg="demo" type="listener" name="listener" ns="$(arg fleet)"/></launch>\n')
    top = ws / "ws/demo/launch/outer.launch"
    top.write_text('<launch><arg name="fleet" default="blue"/>\n'
                   '<include file="$(find demo)/launch/inner.launch"/></launch>\n')
    g = _graph(ws, top)
    assert sorted(g.nodes) == ["/listener"]
    [said] = _said(g)
    assert said.startswith("ws/demo/launch/inner.launch:1:") and "'fleet' has no value" in said
    top.write_text('<launch><arg name="fleet" default="blue"/>\n'
                   '<include file="$(find demo)/launch/inner.launch" pass_all_args="true"/></launch>\n')
    assert sorted(_graph(ws, top).nodes) == ["/blue/listener"]


def test_what_an_include_sets_stays_after_it_unless_a_group_holds_it(ws: Path) -> None:
    _py(ws, "robot.launch.py", ROBOT)
    after = "Node(package='demo', executable='listener', namespace=LaunchConfiguration('robot')),"
    g = _graph(ws, _py(ws, "top.launch.py", "DeclareLaunchArgument('robot', default_value='mine'),\n"
                                            + _include("robot.launch.py", "'robot': 'r2'") + "\n" + after))
    assert sorted(g.nodes) == ["/r2/listener", "/r2/talker"] and _said(g) == []
    # control: the include inside a (scoped) GroupAction: after the group the including file's value
    g = _graph(ws, _py(ws, "top.launch.py", "DeclareLaunchArgument('robot', default_value='mine'),\n"
                                            "GroupAction([\n" + _include("robot.launch.py", "'robot': 'r2'")
                                            + "\n]),\n" + after))
    assert sorted(g.nodes) == ["/mine/listener", "/r2/talker"] and _said(g) == []


def test_an_unscoped_group_keeps_what_it_sets(ws: Path) -> None:
    inside = "SetLaunchConfiguration('fleet', 'green'),"
    g = _graph(ws, _py(ws, "group.launch.py", f"GroupAction([{inside}], scoped=False),\n{UNDECLARED}"))
    assert sorted(g.nodes) == ["/green/listener"] and _said(g) == []
    # control: a scoped group forgets it: the argument has no value, said at the node
    g = _graph(ws, _py(ws, "group.launch.py", f"GroupAction([{inside}]),\n{UNDECLARED}"))
    assert sorted(g.nodes) == ["/listener"]
    [said] = _said(g)
    assert "group.launch.py:" in said and "'fleet' has no value" in said


def test_a_group_without_forwarding_starts_from_its_kept_configurations(ws: Path) -> None:
    body = ("DeclareLaunchArgument('fleet', default_value='blue'),\n"
            "DeclareLaunchArgument('robot', default_value='outer'),\n"
            "GroupAction([\n"
            "    Node(package='demo', executable='talker', namespace=LaunchConfiguration('robot')),\n"
            "    Node(package='demo', executable='listener', namespace=LaunchConfiguration('fleet')),\n"
            "], launch_configurations={'robot': 'kept'}{flag}),")
    g = _graph(ws, _py(ws, "group.launch.py", body.replace("{flag}", ", forwarding=False")))
    assert sorted(g.nodes) == ["/kept/talker", "/listener"]
    [said] = _said(g)
    assert "'fleet' has no value" in said
    # control: forwarding (launch's default): the outer configurations are seen, the kept one set over them
    g = _graph(ws, _py(ws, "group.launch.py", body.replace("{flag}", "")))
    assert sorted(g.nodes) == ["/blue/listener", "/kept/talker"] and _said(g) == []


XML_ROBOT = ('<launch>\n<arg name="robot" default="fallback"/>\n'
             '<node pkg="demo" exec="talker" namespace="$(var robot)"/>\n'
             '<node pkg="demo" exec="listener" namespace="$(var fleet)"/>\n</launch>\n')


def test_ros2_xml_includes_give_and_inherit_arguments(ws: Path) -> None:
    (ws / "ws/demo/launch/robot.launch.xml").write_text(XML_ROBOT)
    top = ws / "ws/demo/launch/top.launch.xml"
    top.write_text('<launch>\n<let name="fleet" value="blue"/>\n'
                   '<include file="$(find-pkg-share demo)/launch/robot.launch.xml">\n'
                   '  <arg name="robot" value="r2"/>\n</include>\n</launch>\n')
    g = _graph(ws, top)
    assert sorted(g.nodes) == ["/blue/listener", "/r2/talker"] and _said(g) == []
    # control: a group without forwarding around the include: only its kept configuration reaches it
    top.write_text('<launch>\n<let name="fleet" value="blue"/>\n<group forwarding="false">\n'
                   '  <keep name="robot" value="r3"/>\n'
                   '  <include file="$(find-pkg-share demo)/launch/robot.launch.xml"/>\n</group>\n</launch>\n')
    g = _graph(ws, top)
    assert sorted(g.nodes) == ["/listener", "/r3/talker"]
    [said] = _said(g)
    assert said.startswith("ws/demo/launch/robot.launch.xml:4:") and "'fleet' has no value" in said



def test_push_and_pop_of_launch_configurations_restore_them(ws: Path) -> None:
    body = ("{push}SetLaunchConfiguration('fleet', 'green'),\n{pop}" + UNDECLARED)
    g = _graph(ws, _py(ws, "stack.launch.py", body.format(push="PushLaunchConfigurations(),\n",
                                                          pop="PopLaunchConfigurations(),\n")))
    assert sorted(g.nodes) == ["/listener"]
    [said] = _said(g)
    assert "'fleet' has no value" in said
    # control: without the push and the pop what is set stays
    g = _graph(ws, _py(ws, "stack.launch.py", body.format(push="", pop="")))
    assert sorted(g.nodes) == ["/green/listener"] and _said(g) == []
    # a pop with no push before it is said at its line
    g = _graph(ws, _py(ws, "stack.launch.py", body.format(push="", pop="PopLaunchConfigurations(),\n")))
    assert sorted(g.nodes) == ["/green/listener"]
    [said] = _said(g)
    assert "stack.launch.py:" in said and "without a PushLaunchConfigurations" in said


def test_reset_launch_configurations_keeps_only_the_ones_it_is_given(ws: Path) -> None:
    body = ("DeclareLaunchArgument('fleet', default_value='blue'),\n"
            "DeclareLaunchArgument('robot', default_value='outer'),\n"
            "{reset}"
            "Node(package='demo', executable='talker', namespace=LaunchConfiguration('robot')),\n" + UNDECLARED)
    g = _graph(ws, _py(ws, "reset.launch.py", body.format(
        reset="ResetLaunchConfigurations({'robot': LaunchConfiguration('fleet')}),\n")))
    assert sorted(g.nodes) == ["/blue/talker", "/listener"]
    [said] = _said(g)
    assert "'fleet' has no value" in said
    # control: no reset
    g = _graph(ws, _py(ws, "reset.launch.py", body.format(reset="")))
    assert sorted(g.nodes) == ["/blue/listener", "/outer/talker"] and _said(g) == []
    # XML's <reset> with <keep> children alike
    top = ws / "ws/demo/launch/reset.launch.xml"
    top.write_text('<launch>\n<let name="fleet" value="blue"/>\n<reset>\n  <keep name="robot" value="$(var fleet)"/>\n'
                   '</reset>\n<node pkg="demo" exec="talker" namespace="$(var robot)"/>\n'
                   '<node pkg="demo" exec="listener" namespace="$(var fleet)"/>\n</launch>\n')
    g = _graph(ws, top)
    assert sorted(g.nodes) == ["/blue/talker", "/listener"]
    [said] = _said(g)
    assert said.startswith("ws/demo/launch/reset.launch.xml:7:") and "'fleet' has no value" in said
