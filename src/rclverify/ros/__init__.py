"""The ROS computation graph read from a robot's software, and contracts
grounded in it (issue 22; docs/ros.md).

Modules, lowest first: ``model`` (graph values, JSON), ``names`` (ROS name
resolution), ``xmlsrc`` (located XML through lxml), ``packages``
(``package.xml`` via catkin_pkg), ``interfaces`` (``.msg/.srv/.action/.idl``
via rosbags' type system), ``sources_py`` / ``sources_cpp`` (node sources via
``ast`` and tree-sitter-cpp), ``executables`` (executable name -> source
files), ``launch_ros1`` / ``launch_ros2`` (launch files read statically),
``bag`` (recorded runs), ``master`` (a live ROS 1 master), ``cache``
(per-file parse cache keyed by sha256), ``graph`` (the scan), ``check``
(grounding findings; ``ground_services`` for services and actions),
``diff`` (the code's graph against a master or a bag, ``ros diff``),
``skeleton`` (``init --from-ros``).
"""
