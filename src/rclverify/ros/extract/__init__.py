"""ROS layer a: the robot's code read into graph records.

C++ and Python sources through tree-sitter, CMake, package manifests,
launch files (ROS 1 XML, ROS 2 Python), parameters, nodelets, plugins,
message definitions (``interfaces``), and the records they fill
(``model``, ``names``).
"""
